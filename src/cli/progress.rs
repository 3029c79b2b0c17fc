//! The CLI edge of progress: a bar where stderr is a terminal; elsewhere (a Slurm task's log, CI,
//! `2> log`) a plain line at each stage's start and end and every [`PLAIN_EVERY`] between, with
//! what is done, the total and the time left. Keeps the views an engine counted over a run's
//! stages (the year, its sky views, EnergyPlus's diffuse ratios) for the closing line.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use sunlit::year::annual::Progress;
use sunlit::{Error, Result};

/// How often a plain progress line is written when stderr is not a terminal: often enough that a
/// log read with `tail -f` shows a live run within a quarter of a minute, rarely enough that a
/// day-long run writes fewer than 6,000 lines.
pub const PLAIN_EVERY: Duration = Duration::from_secs(15);

/// Shortens [`PLAIN_EVERY`] to this many milliseconds. For the tests only (tests/annual.rs): a
/// test cannot wait 15 s for a line, nor count on a small run lasting that long.
const PLAIN_EVERY_ENV: &str = "SUNLIT_PROGRESS_EVERY_MS";

/// A run's progress on stderr, stage by stage.
pub struct Meter {
    /// What the run counts ("views", "instants").
    unit: &'static str,
    out: Out,
    stage: String,
    started: Instant,
    last: Progress,
    /// Views counted by the stages before this one.
    counted_before: usize,
}

enum Out {
    Bar(indicatif::ProgressBar),
    Plain(Throttle),
}

impl Meter {
    /// A bar if stderr is a terminal, plain lines otherwise; the first stage is `stage`, counting `unit`.
    pub fn new(stage: &str, unit: &'static str) -> Result<Self> {
        let out = if std::io::stderr().is_terminal() {
            let style = indicatif::ProgressStyle::with_template("{prefix} [{bar:40}] {pos}/{len} {msg}")
                .map_err(|e| Error::argument("progress", e.to_string()))?;
            Out::Bar(indicatif::ProgressBar::new(0).with_style(style))
        } else {
            Out::Plain(Throttle::new(plain_every()))
        };
        let mut meter = Meter { unit, out, stage: String::new(), started: Instant::now(), last: Progress::default(), counted_before: 0 };
        meter.stage(stage, unit);
        Ok(meter)
    }

    /// Starts a new stage counting `unit`: its progress starts again from 0, the views counted so
    /// far are kept.
    pub fn stage(&mut self, name: &str, unit: &'static str) {
        self.unit = unit;
        self.counted_before += self.last.counted();
        self.last = Progress::default();
        self.stage = name.to_string();
        self.started = Instant::now();
        match &mut self.out {
            Out::Bar(bar) => bar.set_prefix(name.to_string()),
            Out::Plain(throttle) => throttle.last = None,
        }
    }

    /// Shows `p`, the current stage's progress (a plain line only when one is due).
    pub fn report(&mut self, p: Progress) {
        self.last = p;
        let now = Instant::now();
        let elapsed = now.duration_since(self.started);
        match &mut self.out {
            Out::Bar(bar) => {
                bar.set_length(p.total as u64);
                bar.set_position(p.done as u64);
                bar.set_message(format!("{}, {}", self.unit, time_left(&p, elapsed)));
            }
            Out::Plain(throttle) => {
                if throttle.due(now) || p.done >= p.total {
                    eprintln!("{}", plain_line(&self.stage, self.unit, &p, elapsed));
                }
            }
        }
    }

    /// A `progress(done, total)` callback for stages that count without settling any.
    pub fn counts(&mut self) -> impl FnMut(usize, usize) + '_ {
        move |done, total| self.report(Progress::counting(done, total))
    }

    /// Views an engine counted in all stages so far (settled views are not counted).
    pub fn counted(&self) -> usize {
        self.counted_before + self.last.counted()
    }

    /// Removes the bar (plain lines stay in the log).
    pub fn finish(&self) {
        if let Out::Bar(bar) = &self.out {
            bar.finish_and_clear();
        }
    }
}

/// [`PLAIN_EVERY`], or the tests' shorter interval.
fn plain_every() -> Duration {
    std::env::var(PLAIN_EVERY_ENV).ok().and_then(|ms| ms.parse().ok()).map_or(PLAIN_EVERY, Duration::from_millis)
}

/// Whether a plain line is due: the first of a stage, then one per interval.
struct Throttle {
    every: Duration,
    last: Option<Instant>,
}

impl Throttle {
    fn new(every: Duration) -> Self {
        Throttle { every, last: None }
    }

    /// True (and the interval starts again) if no line was written in the last interval.
    fn due(&mut self, now: Instant) -> bool {
        let due = self.last.is_none_or(|last| now.duration_since(last) >= self.every);
        if due {
            self.last = Some(now);
        }
        due
    }
}

/// One plain line: `year: 1,200 of 4,000 views (30 %), 700 counted; 12 s elapsed, 9 s to 47 s left`.
fn plain_line(stage: &str, unit: &str, p: &Progress, elapsed: Duration) -> String {
    let percent = (p.done.min(p.total) * 100).checked_div(p.total).unwrap_or(100);
    let counted = if p.settled > 0 || p.may_settle > 0 { format!(", {} counted", thousands(p.counted())) } else { String::new() };
    format!(
        "{stage}: {} of {} {unit} ({percent} %){counted}; {} elapsed, {}",
        thousands(p.done),
        thousands(p.total),
        span(elapsed.as_secs_f64()),
        time_left(p, elapsed)
    )
}

/// The time left at the stage's rate of counting so far. While views may still be settled
/// without counting, a range: from counting only those that surely will be, to counting all.
fn time_left(p: &Progress, elapsed: Duration) -> String {
    let remaining = p.total.saturating_sub(p.done);
    if remaining == 0 {
        return "done".to_string();
    }
    let counted = p.counted();
    if counted == 0 {
        return "time left not yet known".to_string();
    }
    let per_view = elapsed.as_secs_f64() / counted as f64;
    let surely = remaining.saturating_sub(p.may_settle);
    if surely == remaining {
        format!("about {} left", span(per_view * remaining as f64))
    } else {
        format!("{} to {} left", span(per_view * surely as f64), span(per_view * remaining as f64))
    }
}

/// Seconds as a reader wants them: `40 s`, `3 min 20 s`, `2 h 5 min`.
fn span(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {} s", s / 60, s % 60),
        _ => format!("{} h {} min", s / 3600, s % 3600 / 60),
    }
}

/// `5791143` as `5,791,143`.
fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plain_line_is_due_at_the_start_then_once_per_interval() {
        let t0 = Instant::now();
        let mut throttle = Throttle::new(PLAIN_EVERY);
        let at = |s: f64| t0 + Duration::from_secs_f64(s);
        let written: Vec<f64> =
            [0.0, 1.0, 14.9, 15.0, 16.0, 29.9, 30.0, 31.0, 100.0].into_iter().filter(|&s| throttle.due(at(s))).collect();
        assert_eq!(written, [0.0, 15.0, 30.0, 100.0]);
        assert!((10..=30).contains(&PLAIN_EVERY.as_secs()), "the issue asks for a line every 10–30 s");
    }

    #[test]
    fn a_plain_line_says_done_total_and_time_left() {
        let p = Progress::counting(250, 1_000);
        assert_eq!(
            plain_line("sky", "views", &p, Duration::from_secs(10)),
            "sky: 250 of 1,000 views (25 %); 10 s elapsed, about 30 s left"
        );
        // Samples counted, the year's timesteps not yet fitted: 100 views surely left of 1,100.
        let year = Progress { done: 400, total: 1_500, settled: 0, may_settle: 1_000 };
        assert_eq!(
            plain_line("year", "views", &year, Duration::from_secs(8)),
            "year: 400 of 1,500 views (26 %), 400 counted; 8 s elapsed, 2 s to 22 s left"
        );
        // Fitted: 900 timesteps settled, 100 left to count, all surely counted.
        let fitted = Progress { done: 1_400, total: 1_500, settled: 900, may_settle: 0 };
        assert_eq!(
            plain_line("year", "views", &fitted, Duration::from_secs(100)),
            "year: 1,400 of 1,500 views (93 %), 500 counted; 1 min 40 s elapsed, about 20 s left"
        );
        assert_eq!(time_left(&Progress::counting(0, 10), Duration::from_secs(3)), "time left not yet known");
        assert_eq!(time_left(&Progress::counting(10, 10), Duration::from_secs(3)), "done");
    }

    #[test]
    fn spans_and_thousands_read_as_written() {
        assert_eq!([span(0.4), span(59.4), span(200.0), span(7_500.0)], ["0 s", "59 s", "3 min 20 s", "2 h 5 min"]);
        assert_eq!([thousands(0), thousands(999), thousands(1_000), thousands(5_791_143)], ["0", "999", "1,000", "5,791,143"]);
    }

    #[test]
    fn views_counted_add_up_over_stages_without_the_settled_ones() {
        let mut meter = Meter {
            unit: "views",
            out: Out::Plain(Throttle::new(Duration::from_secs(3600))),
            stage: "year".into(),
            started: Instant::now(),
            last: Progress::default(),
            counted_before: 0,
        };
        meter.report(Progress { done: 1_400, total: 1_500, settled: 900, may_settle: 0 });
        meter.report(Progress { done: 1_500, total: 1_500, settled: 900, may_settle: 0 });
        meter.stage("sky", "views");
        meter.report(Progress::counting(145, 145));
        assert_eq!(meter.counted(), 600 + 145);
    }
}
