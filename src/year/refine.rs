//! Refined timesteps counted sparsely: where the refinement rules of [`super::annual`] ask for a
//! timestep to be counted directly (and no certificate settled it, [`super::certified`]), the
//! steps of one receiver at one time of day on consecutive days are counted by bisection in days
//! and the rest interpolated linearly between counted days, only where that is as good as
//! counting.
//!
//! Why days: at a fixed clock time the sun moves at most about 0.4° a day, so a receiver's
//! fraction at that time changes slowly and smoothly from day to day, except where a shadow edge
//! enters or leaves it (a kink) or where it goes dark. The refined cells of the spline are those
//! where the fraction changes too fast *within a day* (the spread rule) or has a kink between
//! sample days 13.5 days apart (`KINK`); along the days of one time of day most of them are
//! still nearly straight, and a handful of counted days carries them.
//!
//! The rules, so that no step becomes less exact than counting it would make it where that matters:
//! - the first and last day of every run are counted;
//! - a span between counted days whose ends are not both lit (≥ [`NEAR_DARK`]) and of the same
//!   kind (both partly lit, or both wholly lit) is counted step by step, as before: a dark/lit
//!   edge, a sliver of sun in a dark canyon or a shadow entering a wholly lit surface is never
//!   interpolated. Such a span is first handed to a [`SpanProver`] (the year's certificates over
//!   the span's suns, [`super::certified::SpanProofs`]): the steps it proves dark or lit take the
//!   value counting them would give, exactly, and are not counted;
//! - otherwise its middle day is counted, and the span is interpolated (piecewise linearly
//!   through the middle) only if the middle lies within [`TOLERANCE`] of the straight line
//!   between its ends, is of the same kind, and no counted day is more than [`MAX_GAP`] days
//!   from the next; else each half is taken the same way.
//!
//! A step the many-caster proofs showed dark ([`super::certified::ToCount`]) is known before
//! any round: it is never counted, but it is read where the rules read a counted one, so the
//! steps counted and interpolated around it are those counting it would give.
//!
//! So the views only go down: every refined step is counted at most once. Measured against
//! counting every timestep in docs/energyplus-fidelity.md ("Refined steps counted sparsely").

use crate::count::certify::Wanted;
use crate::count::{Engine, ViewRequest};
use crate::error::Result;
use crate::year::annual::{NEAR_DARK, Progress, Views};
use crate::year::certified::{Rough, tally};

/// How far, at most, a counted value may lie from the straight line between the counted days
/// around it for the days between to be interpolated.
pub const TOLERANCE: f64 = 0.01;

/// The most days between two counted days that are interpolated across.
pub const MAX_GAP: usize = 4;

/// A counted fraction this close to 1 is wholly lit.
const WHOLLY_LIT: f64 = 1.0 - 1e-9;

/// What a counted fraction says about the steps around it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// Dark or nearly: a span touching it is counted step by step.
    Dark,
    Partly,
    Wholly,
}

fn kind(v: f64) -> Kind {
    if v < NEAR_DARK {
        Kind::Dark
    } else if v >= WHOLLY_LIT {
        Kind::Wholly
    } else {
        Kind::Partly
    }
}

/// The refined steps of one year, their values as they are counted or interpolated, and the
/// spans still open.
pub(super) struct Sparse {
    /// Per step (index into the refined steps): its value once counted or interpolated.
    values: Vec<Option<f64>>,
    /// The steps grouped into runs: steps of one fitted piece at one time of day on consecutive
    /// days, in day order, run after run.
    order: Vec<usize>,
    /// Each run's positions in `order` (ranges, not a list each: a city has millions of steps).
    runs: Vec<std::ops::Range<usize>>,
    /// Spans (run, first, last position) whose ends are counted and whose inside is not known.
    spans: Vec<(usize, usize, usize)>,
    /// Of `spans`, those whose middle is asked this round (the rest are counted whole).
    asked_middles: Vec<(usize, usize, usize)>,
    /// Steps counted so far.
    counted: usize,
    /// Steps a span proof settled ([`SpanProver`]).
    proved: usize,
    /// Per step: whether it was counted (not interpolated).
    was_counted: Vec<bool>,
    /// Whether the first round (every run's ends) was asked.
    started: bool,
}

impl Sparse {
    /// Groups `rough` (the steps to count, `rows_per_day` rows a day) into runs; the steps
    /// `known_dark` marks are known to be 0 and never asked.
    pub(super) fn new(rough: &[Rough], known_dark: &[bool], rows_per_day: usize) -> Self {
        let key = |i: usize| {
            let (r, row) = (&rough[i], rough[i].row as usize);
            (r.cell.0, r.cell.1, row % rows_per_day, row / rows_per_day)
        };
        let mut order: Vec<usize> = (0..rough.len()).collect();
        order.sort_by_key(|&i| key(i));
        let mut runs = Vec::new();
        for run in order.chunk_by(|&a, &b| {
            let (ka, kb) = (key(a), key(b));
            (ka.0, ka.1, ka.2) == (kb.0, kb.1, kb.2) && kb.3 == ka.3 + 1
        }) {
            let start = runs.last().map_or(0, |r: &std::ops::Range<usize>| r.end);
            runs.push(start..start + run.len());
        }
        Sparse {
            values: (0..rough.len()).map(|i| known_dark.get(i).copied().unwrap_or(false).then_some(0.0)).collect(),
            order,
            runs,
            spans: Vec::new(),
            asked_middles: Vec::new(),
            counted: 0,
            proved: 0,
            was_counted: vec![false; rough.len()],
            started: false,
        }
    }

    /// Steps neither counted nor interpolated yet: the most that may still be counted.
    pub(super) fn unsettled(&self) -> usize {
        self.values.iter().filter(|v| v.is_none()).count()
    }

    /// Steps counted so far.
    pub(super) fn counted(&self) -> usize {
        self.counted
    }

    /// Steps a span proof settled so far.
    pub(super) fn proved(&self) -> usize {
        self.proved
    }

    /// Whether every step has its value: no span is open and no middle awaits its answer.
    pub(super) fn done(&self) -> bool {
        self.started && self.spans.is_empty() && self.asked_middles.is_empty()
    }

    /// The steps to count next (indices into the refined steps), those already known left out:
    /// may be empty while [`Self::done`] is not (every middle asked was known); answer it then.
    /// The spans this round counts step by step are first handed to `prover`, and the steps it
    /// settles are not counted.
    pub(super) fn next_round(&mut self, prover: &dyn SpanProver) -> Vec<usize> {
        let (mut asked, whole) = self.asked();
        let whole: Vec<(Vec<usize>, Wanted)> = whole
            .into_iter()
            .map(|(steps, wanted)| (steps.into_iter().filter(|&i| self.values[i].is_none()).collect::<Vec<_>>(), wanted))
            .filter(|(steps, _)| steps.len() >= MIN_PROVED_SPAN)
            .collect();
        if !whole.is_empty() {
            for (i, v) in prover.prove(&whole) {
                if self.values[i].is_none() {
                    self.values[i] = Some(v);
                    self.proved += 1;
                }
            }
        }
        asked.retain(|&i| self.values[i].is_none());
        asked
    }

    /// The steps the rules ask for next, known or not, and the spans among them counted step by
    /// step, with the certificates their ends make worth looking for.
    fn asked(&mut self) -> (Vec<usize>, Vec<(Vec<usize>, Wanted)>) {
        if !self.started {
            self.started = true;
            return (self.first_round(), Vec::new());
        }
        let (mut asked, mut whole) = (Vec::new(), Vec::new());
        for (run, a, b) in std::mem::take(&mut self.spans) {
            let steps = self.run(run);
            let (va, vb) = (self.value(steps[a]), self.value(steps[b]));
            if interpolable(va, vb) {
                asked.push(steps[(a + b) / 2]);
                self.asked_middles.push((run, a, b));
            } else {
                let inner = &steps[a + 1..b];
                asked.extend(inner.iter().copied());
                whole.push((inner.to_vec(), span_wanted(va, vb)));
            }
        }
        (asked, whole)
    }

    /// Every run's first and last day, and the whole of runs of one or two days.
    fn first_round(&mut self) -> Vec<usize> {
        let mut asked = Vec::new();
        for run in 0..self.runs.len() {
            let steps = self.run(run);
            let last = steps.len() - 1;
            asked.push(steps[0]);
            if last > 0 {
                asked.push(steps[last]);
            }
            if last > 1 {
                self.spans.push((run, 0, last));
            }
        }
        asked
    }

    /// Takes the counts of `asked` (as returned by [`Self::next_round`]) and decides the spans
    /// whose middles they were: interpolated, or halved for the next round.
    pub(super) fn answer(&mut self, asked: &[usize], values: &[f64]) {
        for (&i, &v) in asked.iter().zip(values) {
            self.values[i] = Some(v);
            self.was_counted[i] = true;
        }
        self.counted += asked.len();
        for (run, a, b) in std::mem::take(&mut self.asked_middles) {
            let m = (a + b) / 2;
            let steps = self.run(run);
            let (va, vm, vb) = (self.value(steps[a]), self.value(steps[m]), self.value(steps[b]));
            let straight = va + (vb - va) * (m - a) as f64 / (b - a) as f64;
            let agrees = kind(vm) == kind(va) && (vm - straight).abs() <= TOLERANCE;
            if agrees && b - a <= 2 * MAX_GAP {
                self.interpolate(run, a, m);
                self.interpolate(run, m, b);
            } else {
                for (x, y) in [(a, m), (m, b)] {
                    if y > x + 1 {
                        self.spans.push((run, x, y));
                    }
                }
            }
        }
    }

    /// Fills the steps strictly between positions `a` and `b` of `run` on the straight line
    /// between their counted values.
    fn interpolate(&mut self, run: usize, a: usize, b: usize) {
        let (va, vb) = (self.value(self.run(run)[a]), self.value(self.run(run)[b]));
        for p in a + 1..b {
            let step = self.run(run)[p];
            // A step proved dark keeps its 0 (counting it would not: it would be interpolated).
            if self.values[step].is_none() {
                self.values[step] = Some(va + (vb - va) * (p - a) as f64 / (b - a) as f64);
            }
        }
    }

    /// Run `k`'s steps, in day order.
    fn run(&self, k: usize) -> &[usize] {
        &self.order[self.runs[k].clone()]
    }

    fn value(&self, step: usize) -> f64 {
        self.values[step].unwrap_or(0.0)
    }

    /// Every step's value, once [`Self::next_round`] returns nothing.
    pub(super) fn values(self) -> Vec<f64> {
        self.values.into_iter().map(|v| v.unwrap_or(0.0)).collect()
    }
}

/// Which certificate a span counted step by step whose ends count `a` and `b` may hold: dark
/// beside a dark end (a canyon's dark days, a sliver of sun among them counted), lit beside a
/// wholly lit one (the days before a shadow enters).
fn span_wanted(a: f64, b: f64) -> Wanted {
    Wanted { dark: kind(a) == Kind::Dark || kind(b) == Kind::Dark, lit: kind(a) == Kind::Wholly || kind(b) == Kind::Wholly }
}

/// Spans with fewer unknown steps than this are counted without looking for a proof: one view
/// costs about what a proof does.
const MIN_PROVED_SPAN: usize = 2;

/// Proves steps of spans the refinement would count step by step dark or lit instead: the
/// steps of one receiver at one time of day on consecutive days, whose suns lie along a short
/// arc, so a certificate over them is much likelier than over a whole sample cell.
pub(super) trait SpanProver {
    /// For spans (steps and what to look for), the steps proved and their exact values (0 or 1).
    fn prove(&self, spans: &[(Vec<usize>, Wanted)]) -> Vec<(usize, f64)>;

    /// Proofs tried and steps proved so far, for the year's log.
    fn ledger(&self) -> (usize, usize) {
        (0, 0)
    }
}

/// A prover that proves nothing: every span is counted step by step.
pub(super) struct NoProofs;

impl SpanProver for NoProofs {
    fn prove(&self, _: &[(Vec<usize>, Wanted)]) -> Vec<(usize, f64)> {
        Vec::new()
    }
}

/// Whether a span whose ends count `a` and `b` may be interpolated at all: both lit, of one kind.
fn interpolable(a: f64, b: f64) -> bool {
    kind(a) != Kind::Dark && kind(a) == kind(b)
}

/// Counts the refined steps `rough` sparsely ([`Sparse`]) and returns every step's fraction, in
/// order; the steps `known_dark` marks are 0 and not counted. `request` gives a step's view;
/// `report` gets, with each progress report, the most refined steps that may in all be counted
/// (those counted so far and those still open).
pub(super) async fn count_sparsely(
    views: &Views<'_, impl Engine>,
    rough: &[Rough],
    known_dark: &[bool],
    rows_per_day: usize,
    request: &dyn Fn(&Rough) -> ViewRequest,
    prover: &dyn SpanProver,
    report: &mut dyn FnMut(usize, Progress) -> Result<()>,
) -> Result<Vec<f64>> {
    let mut sparse = Sparse::new(rough, known_dark, rows_per_day);
    loop {
        let to_count = sparse.counted() + sparse.unsettled();
        let asked = sparse.next_round(prover);
        if asked.is_empty() {
            if sparse.done() {
                break;
            }
            sparse.answer(&[], &[]);
            continue;
        }
        let requests: Vec<ViewRequest> = asked.iter().map(|&i| request(&rough[i])).collect();
        let before = sparse.counted();
        let values = views.count(&requests, &mut |p| report(to_count, Progress::counting(before + p.done, to_count))).await?;
        sparse.answer(&asked, &values);
    }
    // The last round's interpolated steps are settled too: the year ends at its total.
    let counted = sparse.counted();
    report(counted, Progress::counting(counted, counted))?;
    let (tried, _) = prover.ledger();
    log::info!(
        "refinement: {} of {} steps counted, {} proved in spans ({tried} span proofs tried), the rest interpolated \
         between counted days",
        sparse.counted(),
        rough.len(),
        sparse.proved()
    );
    // The tally walks every refined step again: only when someone reads it.
    if log::log_enabled!(log::Level::Info) {
        log::info!("refinement by rule (steps / counted): {}", tally(rough.iter().zip(sparse.was_counted.iter().copied())));
    }
    Ok(sparse.values())
}

#[cfg(test)]
mod tests;
