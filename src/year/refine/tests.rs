//! Sparse counting of refined steps against counting every one of them, on fractions given as
//! functions of the day (one receiver, one time of day).

use super::*;
use crate::year::certified::Rule;

/// Rows a day in these tests (Timestep 4).
const ROWS: usize = 96;

/// A refined step of fitted piece `fit` at time of day `slot` on day `day` (0-based).
fn step(fit: usize, slot: usize, day: usize) -> Rough {
    // Samples from 0 to 1: neither certificate is worth looking for.
    Rough::new(day * ROWS + slot, fit, (0, fit, 0, 0), (0.0, 1.0), Rule::Spread)
}

/// Runs the rounds of [`Sparse`] with `truth` answering every asked step: each step's value and
/// how many were counted.
fn sparse(rough: &[Rough], truth: impl Fn(&Rough) -> f64) -> (Vec<f64>, usize) {
    sparse_knowing(rough, &[], truth)
}

/// [`sparse`] with the steps `known_dark` marks known to be 0 before any round: they must never
/// be asked.
fn sparse_knowing(rough: &[Rough], known_dark: &[bool], truth: impl Fn(&Rough) -> f64) -> (Vec<f64>, usize) {
    sparse_proving(rough, known_dark, &NoProofs, truth)
}

/// [`sparse_knowing`] with `prover` settling spans counted step by step.
fn sparse_proving(rough: &[Rough], known_dark: &[bool], prover: &dyn SpanProver, truth: impl Fn(&Rough) -> f64) -> (Vec<f64>, usize) {
    let mut s = Sparse::new(rough, known_dark, ROWS);
    let mut asked_ever = vec![false; rough.len()];
    loop {
        let asked = s.next_round(prover);
        if asked.is_empty() {
            if s.done() {
                break;
            }
            s.answer(&[], &[]);
            continue;
        }
        assert!(asked.iter().all(|&i| !known_dark.get(i).copied().unwrap_or(false)), "a known step was asked");
        for &i in &asked {
            assert!(!asked_ever[i], "step {i} asked twice");
            asked_ever[i] = true;
        }
        let values: Vec<f64> = asked.iter().map(|&i| truth(&rough[i])).collect();
        s.answer(&asked, &values);
    }
    assert_eq!(s.unsettled(), 0, "every step has a value");
    let counted = s.counted();
    (s.values(), counted)
}

/// One run of `days` consecutive days at one time of day, with `f(day)` its fraction.
fn run(days: usize, f: impl Fn(usize) -> f64) -> (Vec<f64>, Vec<f64>, usize) {
    let rough: Vec<Rough> = (0..days).map(|d| step(0, 40, d)).collect();
    let (values, counted) = sparse(&rough, |r| f(r.row as usize / ROWS));
    ((0..days).map(f).collect(), values, counted)
}

fn largest_error(truth: &[f64], values: &[f64]) -> f64 {
    truth.iter().zip(values).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max)
}

/// A sliver of sun on one day in a run dark at both ends (a slot's minutes of sun at this time of
/// day): every step is counted, so the sliver is kept. Bisection alone would miss it: day 16 lies
/// between the counted days 14 and 17, which are dark.
#[test]
fn a_short_lit_piece_between_dark_days_is_counted_whole() {
    let (truth, values, counted) = run(30, |d| if d == 16 { 0.4 } else { 0.0 });
    assert_eq!(values, truth);
    assert_eq!(counted, 30);
}

/// Partly lit at both ends and dark for eight days in between: the middle day that falls dark
/// makes the halves touching it counted step by step, so no dark step is interpolated as lit and
/// the days around the spell are counted; the lit days well away from it are interpolated.
#[test]
fn a_dark_spell_between_lit_days_is_not_interpolated_across() {
    let f = |d: usize| if (26..34).contains(&d) { 0.0 } else { 0.5 + 0.001 * d as f64 };
    let (truth, values, counted) = run(40, f);
    for (d, (t, v)) in truth.iter().zip(&values).enumerate() {
        assert_eq!(*t == 0.0, *v == 0.0, "day {d}: {t} against {v}");
        if (25..=34).contains(&d) {
            assert_eq!(t, v, "day {d} at the edges is counted");
        }
    }
    assert!(counted < 40, "the lit days away from the spell are interpolated: {counted} counted");
}

/// A shadow entering a wholly lit surface: 1 up to day 9, then falling. The span between a
/// wholly lit day and a partly lit one is counted, so the kink where the shadow enters is exact.
#[test]
fn a_shadow_entering_a_wholly_lit_surface_is_counted() {
    let f = |d: usize| if d < 10 { 1.0 } else { 1.0 - 0.02 * (d - 9) as f64 };
    let (truth, values, _) = run(30, f);
    for d in 5..15 {
        assert_eq!(truth[d], values[d], "day {d}");
    }
    assert!(largest_error(&truth, &values) <= TOLERANCE);
}

/// A smooth fraction is carried by few counted days, within the tolerance everywhere.
#[test]
fn a_smooth_fraction_is_interpolated_within_the_tolerance() {
    let f = |d: usize| 0.5 + 0.2 * (d as f64 / 20.0).sin();
    let (truth, values, counted) = run(41, f);
    let error = largest_error(&truth, &values);
    println!("smooth: {counted} of 41 counted, largest error {error:.4}");
    assert!(counted * 2 < 41, "{counted} of 41 counted");
    assert!(error <= TOLERANCE, "largest error {error}");
}

/// A kink inside a partly lit run (a plateau, then a fall) is found by the middle days, and the
/// days around it are counted until the straight lines fit.
#[test]
fn a_kink_between_counted_days_is_followed() {
    let f = |d: usize| if d < 17 { 0.8 } else { 0.8 - 0.015 * (d - 17) as f64 };
    let (truth, values, counted) = run(40, f);
    let error = largest_error(&truth, &values);
    println!("kink: {counted} of 40 counted, largest error {error:.4}");
    assert!(error <= TOLERANCE, "largest error {error}");
    assert!(counted < 40);
}

/// Steps of different times of day, of different pieces, or with a day missing between them
/// are separate runs: a span never reaches across them.
#[test]
fn runs_break_at_gaps_times_of_day_and_pieces() {
    let mut rough = Vec::new();
    for d in (0..10).chain(12..20) {
        rough.push(step(0, 40, d));
        rough.push(step(0, 41, d));
        rough.push(step(1, 40, d));
    }
    let s = Sparse::new(&rough, &[], ROWS);
    let mut lengths: Vec<usize> = s.runs.iter().map(|r| r.len()).collect();
    lengths.sort_unstable();
    assert_eq!(lengths, vec![8, 8, 8, 10, 10, 10]);
    for k in 0..s.runs.len() {
        assert!(s.run(k).windows(2).all(|w| rough[w[1]].row as usize == rough[w[0]].row as usize + ROWS), "consecutive days");
    }
}

/// The runs kept as ranges of one sorted list of steps (a city's millions of steps without a
/// list each) are the runs a list each gave, step for step and in order: so every round asks
/// the same steps and takes the same answers, bit for bit.
#[test]
fn runs_as_ranges_are_the_lists_they_replace() {
    // Steps of three pieces and four times of day over days with gaps, in a scrambled order.
    let mut rough = Vec::new();
    for d in (0..40).filter(|d| d % 7 != 3 && d % 11 != 5) {
        for (fit, slot) in [(0, 40), (0, 41), (1, 40), (2, 12)] {
            rough.push(step(fit, slot, d));
        }
    }
    let n = rough.len();
    rough = (0..n).map(|i| rough[(i * 37) % n]).collect();
    // The lists as they were made: the steps sorted by piece, time of day and day, cut where a
    // day is missing.
    let key = |i: usize| (rough[i].cell.0, rough[i].cell.1, rough[i].row as usize % ROWS, rough[i].row as usize / ROWS);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&i| key(i));
    let lists: Vec<Vec<usize>> = order
        .chunk_by(|&a, &b| {
            let (ka, kb) = (key(a), key(b));
            (ka.0, ka.1, ka.2) == (kb.0, kb.1, kb.2) && kb.3 == ka.3 + 1
        })
        .map(<[usize]>::to_vec)
        .collect();
    let s = Sparse::new(&rough, &[], ROWS);
    let ranges: Vec<Vec<usize>> = (0..s.runs.len()).map(|k| s.run(k).to_vec()).collect();
    assert!(lists.len() > 20, "{} runs", lists.len());
    assert_eq!(ranges, lists);
}

/// Steps known dark (the many-caster proofs) are never counted, and the rest come out as they do
/// when those steps are counted: a run lit at its ends with a dark spell, a run whose first
/// days are dark, and a lit run with one dark day inside a span that counting would interpolate
/// (known, it keeps its 0). Failed with the known steps asked (counted as before) and with
/// `interpolate` overwriting them.
#[test]
fn steps_known_dark_are_not_counted_and_move_no_other_value() {
    let spell = |d: usize| if (26..34).contains(&d) { 0.0 } else { 0.5 + 0.001 * d as f64 };
    let early = |d: usize| if d < 12 { 0.0 } else { 0.3 + 0.002 * d as f64 };
    for f in [&spell as &dyn Fn(usize) -> f64, &early] {
        let rough: Vec<Rough> = (0..40).map(|d| step(0, 40, d)).collect();
        let truth = |r: &Rough| f(r.row as usize / ROWS);
        let known: Vec<bool> = rough.iter().map(|r| truth(r) == 0.0).collect();
        let (counting, counted) = sparse(&rough, truth);
        let (knowing, counted_knowing) = sparse_knowing(&rough, &known, truth);
        assert_eq!(knowing, counting);
        let dark = known.iter().filter(|k| **k).count();
        assert!(dark > 0 && counted_knowing + dark <= counted, "{counted_knowing} + {dark} against {counted}");
    }
    // Day 5 dark inside a lit, straight run: counting interpolates across it, knowing keeps it.
    let lit = |d: usize| if d == 5 { 0.0 } else { 0.6 };
    let rough: Vec<Rough> = (0..9).map(|d| step(0, 40, d)).collect();
    let known: Vec<bool> = (0..9).map(|d| d == 5).collect();
    let (counting, _) = sparse(&rough, |r| lit(r.row as usize / ROWS));
    let (knowing, _) = sparse_knowing(&rough, &known, |r| lit(r.row as usize / ROWS));
    assert_eq!(counting[5], 0.6);
    assert_eq!(knowing[5], 0.0);
    assert_eq!(knowing.iter().enumerate().filter(|(d, _)| *d != 5).map(|(_, v)| *v).collect::<Vec<_>>(), vec![0.6; 8]);
}

/// A prover that knows the truth: it proves a span's step dark where it is 0 and lit where it
/// is 1 and the span's ends ask for it, as an exact certificate would; it records what it was
/// handed.
struct Oracle<'a> {
    rough: &'a [Rough],
    truth: &'a dyn Fn(&Rough) -> f64,
    handed: std::cell::RefCell<Vec<usize>>,
}

impl SpanProver for Oracle<'_> {
    fn prove(&self, spans: &[(Vec<usize>, Wanted)]) -> Vec<(usize, f64)> {
        let mut proved = Vec::new();
        for (steps, wanted) in spans {
            self.handed.borrow_mut().extend(steps);
            for &i in steps {
                let v = (self.truth)(&self.rough[i]);
                if (wanted.dark && v == 0.0) || (wanted.lit && v == 1.0) {
                    proved.push((i, v));
                }
            }
        }
        proved
    }
}

/// Spans the refinement counts step by step are handed to the prover first, and what it proves
/// is not counted and moves no value: a dark spell with a sliver of sun in it, a dark start, a
/// wholly lit start before a shadow enters. Only spans that would be counted whole are handed
/// over (never a middle the rules interpolate around).
#[test]
fn steps_proved_in_spans_are_not_counted_and_move_no_value() {
    let spell = |d: usize| {
        if d == 30 {
            0.2
        } else if (20..40).contains(&d) {
            0.0
        } else {
            0.5 + 0.001 * d as f64
        }
    };
    let early = |d: usize| if d < 12 { 0.0 } else { 0.3 + 0.002 * d as f64 };
    let shadow = |d: usize| if d < 15 { 1.0 } else { 0.9 - 0.01 * d as f64 };
    for (k, f) in [&spell as &dyn Fn(usize) -> f64, &early, &shadow].into_iter().enumerate() {
        let rough: Vec<Rough> = (0..50).map(|d| step(0, 40, d)).collect();
        let truth = |r: &Rough| f(r.row as usize / ROWS);
        let (counting, counted) = sparse(&rough, truth);
        let oracle = Oracle { rough: &rough, truth: &truth, handed: Default::default() };
        let (proving, counted_proving) = sparse_proving(&rough, &[], &oracle, truth);
        assert_eq!(proving, counting, "case {k}");
        let handed = oracle.handed.borrow();
        let settled = handed.iter().filter(|&&i| [0.0, 1.0].contains(&truth(&rough[i]))).count();
        assert!(settled > 0 && counted_proving + settled <= counted, "case {k}: {counted_proving} + {settled} against {counted}");
        // Handed over only where counting would count each step: with no proofs, those were counted.
        let mut s = Sparse::new(&rough, &[], ROWS);
        let mut counted_steps = Vec::new();
        loop {
            let asked = s.next_round(&NoProofs);
            if asked.is_empty() && s.done() {
                break;
            }
            let values: Vec<f64> = asked.iter().map(|&i| truth(&rough[i])).collect();
            counted_steps.extend(&asked);
            s.answer(&asked, &values);
        }
        assert!(handed.iter().all(|i| counted_steps.contains(i)), "case {k}: a step counting interpolates was handed over");
    }
}
