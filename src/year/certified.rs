//! Refined timesteps settled by certificate instead of counted: where a sample cell's steps
//! would be counted directly (the refinement rules of [`super::annual`]), the steps of one
//! receiver in one cell are handed together to [`Certifier`], and those it proves dark or lit
//! are set to 0 or 1 without a view.
//!
//! Owns only the grouping and which certificate to look for; the proofs are geometry and live
//! with the counting stage ([`crate::count::certify`]), where the page and both engines share
//! them. Exact either way: a certificate holds at every sun of its steps, so the schedule is what
//! counting them would give, and a step no certificate settles is counted as before.
//!
//! The steps the spline interpolates are handed over too ([`Smooth`], [`never_dark`]): a sliver
//! of shadow between the samples may take a lit cell's receiver wholly dark for a step (a tall
//! block passing the sun in a street canyon), which no rule on the samples can see. A step is
//! interpolated only where some patch of its receiver is proved lit at its sun
//! ([`Certifier::unproved_lit_in_cells`]); the rest are counted, so no dark step is ever interpolated as
//! lit.

use glam::DVec3;

use crate::count::certify::{Certificate, Certifier, Proof, Wanted};
use crate::count::exact::engine::ExactEngine;
use crate::platform::{cpu_seconds, seconds};
use crate::scene::Scene;
use crate::sun::location::Location;
use crate::sun::position::sun_direction;
use crate::year::annual::{Columns, shading_sun_day};
use crate::year::samples::Timesteps;

/// A timestep the refinement counts directly unless a certificate settles it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Rough {
    pub row: usize,
    pub column: usize,
    pub sun: DVec3,
    pub day: f64,
    /// Its sample cell: regime, fitted piece (receiver and lit piece), cell's first day and τ.
    pub cell: (usize, usize, usize, usize),
    /// The lowest and highest of the cell's four samples.
    pub corners: (f64, f64),
    /// The first rule that sent it to counting.
    pub rule: Rule,
}

/// Which refinement rule sent a step to counting (the first that applies, in this order), for
/// the year's tally of what each rule costs ([`tally`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Rule {
    /// Its piece is dark at every sample of the year (no fit).
    NoFit,
    /// The cell's samples differ by more than the refinement threshold.
    Spread,
    /// A sample day of the cell lacks the lit piece (borrowed samples).
    Borrowed,
    /// All four of the cell's samples are under `NEAR_DARK`.
    AllNearDark,
    /// Some, not all, of the cell's samples are under `NEAR_DARK`.
    SomeNearDark,
    /// The fit is under `NEAR_DARK`.
    NearDarkFit,
    /// The fit leaves the cell's bilinear interpolation by more than `KINK`.
    Kink,
    /// Interpolated, but not proved never dark.
    NotNeverDark,
}

impl Rule {
    const ALL: [Rule; 8] = [
        Rule::NoFit,
        Rule::Spread,
        Rule::Borrowed,
        Rule::AllNearDark,
        Rule::SomeNearDark,
        Rule::NearDarkFit,
        Rule::Kink,
        Rule::NotNeverDark,
    ];

    fn name(self) -> &'static str {
        match self {
            Rule::NoFit => "dark at every sample",
            Rule::Spread => "spread",
            Rule::Borrowed => "borrowed day",
            Rule::AllNearDark => "all four samples near dark",
            Rule::SomeNearDark => "some sample near dark",
            Rule::NearDarkFit => "near-dark fit",
            Rule::Kink => "KINK",
            Rule::NotNeverDark => "not proved never dark",
        }
    }
}

/// Per rule, the steps of `steps` and how many of them `marked` holds, as a log line's text
/// ("rule a / b, …", rules with no step left out).
pub(super) fn tally<'a>(steps: impl Iterator<Item = (&'a Rough, bool)>) -> String {
    let mut counts = [(0usize, 0usize); Rule::ALL.len()];
    for (r, marked) in steps {
        let k = Rule::ALL.iter().position(|x| *x == r.rule).unwrap_or(0);
        counts[k].0 += 1;
        counts[k].1 += usize::from(marked);
    }
    let parts: Vec<String> = Rule::ALL
        .iter()
        .zip(counts)
        .filter(|(_, c)| c.0 > 0)
        .map(|(rule, (all, marked))| format!("{} {all} / {marked}", rule.name()))
        .collect();
    parts.join(", ")
}

/// A timestep the spline interpolates, kept small (a city's year has millions): its row,
/// receiver and sample cell (regime, fitted piece, the cell's first day and τ indices).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Smooth {
    pub row: u32,
    pub column: u32,
    pub fit: u32,
    pub regime: u16,
    pub at: (u16, u16),
}

impl Smooth {
    /// The interpolated step at `row` of receiver `column`, in regime `regime`'s fitted piece
    /// `fit` and its sample cell `(k, j)` (first day and τ indices).
    pub(super) fn new(row: usize, column: usize, fit: usize, regime: usize, (k, j): (usize, usize)) -> Self {
        let small = |x: usize| u16::try_from(x).unwrap_or(u16::MAX);
        Smooth { row: row as u32, column: column as u32, fit: fit as u32, regime: small(regime), at: (small(k), small(j)) }
    }
}

/// Interpolated steps proved per batch: bounds the suns held at once.
const SMOOTH_BATCH: usize = 1 << 18;

/// The interpolated steps of `smooth` whose receiver is not proved partly lit at their sun
/// (`sun_of` gives a row's sun and calendar day), as steps to count. The steps of one receiver
/// and fitted piece are proved together, cell by cell in [`block_order`]: runs of neighbouring
/// cells at once (a half of a run is a block of days by times of day), then single cells, then
/// halves of a cell ([`Certifier::unproved_lit_in_cells`]).
pub(super) fn never_dark(certifier: &Certifier, mut smooth: Vec<Smooth>, sun_of: &dyn Fn(usize) -> (DVec3, f64)) -> Vec<Rough> {
    smooth.sort_unstable_by_key(|s| (s.regime, s.fit, block_order(s.at), s.row));
    let pieces: Vec<&[Smooth]> = smooth.chunk_by(|a, b| (a.regime, a.fit) == (b.regime, b.fit)).collect();
    let mut out = Vec::new();
    let mut start = 0;
    while start < pieces.len() {
        // Whole pieces per batch, up to about SMOOTH_BATCH steps.
        let mut end = start;
        let mut steps = 0;
        while end < pieces.len() && (end == start || steps + pieces[end].len() <= SMOOTH_BATCH) {
            steps += pieces[end].len();
            end += 1;
        }
        let batch = &pieces[start..end];
        let suns: Vec<Vec<(DVec3, f64)>> = batch.iter().map(|p| p.iter().map(|s| sun_of(s.row as usize)).collect()).collect();
        let directions: Vec<Vec<DVec3>> = suns.iter().map(|p| p.iter().map(|s| s.0).collect()).collect();
        // Where each cell starts among its piece's steps.
        let starts: Vec<Vec<usize>> = batch.iter().map(|p| (0..p.len()).filter(|&i| i == 0 || p[i].at != p[i - 1].at).collect()).collect();
        let sets: Vec<(usize, &[DVec3], &[usize])> =
            batch.iter().zip(&directions).zip(&starts).map(|((p, d), c)| (p[0].column as usize, d.as_slice(), c.as_slice())).collect();
        for ((piece, suns), unproved) in batch.iter().zip(&suns).zip(certifier.unproved_lit_in_cells(&sets)) {
            out.extend(unproved.into_iter().map(|k| {
                let s = piece[k];
                let (sun, day) = suns[k];
                let key = (usize::from(s.regime), s.fit as usize, usize::from(s.at.0), usize::from(s.at.1));
                Rough { row: s.row as usize, column: s.column as usize, sun, day, cell: key, corners: (1.0, 1.0), rule: Rule::NotNeverDark }
            }));
        }
        start = end;
    }
    out
}

/// A cell's place in an order where each half of a run of cells is a compact block of the
/// sample grid (days by times of day), not a stretch of whole days: the bits of its day and
/// time-of-day indices interleaved, the day's lowest first. A block's suns then span about as
/// much of the sky each way (a cell is some 14 days, a few degrees of declination, by some 40
/// minutes, 10° of hour angle), so its footprints are short and a disc passes between them
/// over more cells: on blaas-louvres 4,029 proofs instead of 6,987 in order of days.
fn block_order((k, j): (u16, u16)) -> u64 {
    spread_bits(k) | spread_bits(j) << 1
}

/// `x`'s bits at the even places of a `u64` (bit b at 2b): the sort calls it for every
/// comparison, where a loop over the bits was 2 % of a year's samples.
fn spread_bits(x: u16) -> u64 {
    let mut x = u64::from(x);
    x = (x | x << 8) & 0x00ff_00ff;
    x = (x | x << 4) & 0x0f0f_0f0f;
    x = (x | x << 2) & 0x3333_3333;
    (x | x << 1) & 0x5555_5555
}

/// Cells with fewer steps to settle than this are counted: one view costs about what a proof
/// does.
const MIN_STEPS: usize = 2;

/// What a settled step becomes.
fn fraction(certificate: Certificate) -> f32 {
    match certificate {
        Certificate::Dark => 0.0,
        Certificate::Lit => 1.0,
    }
}

/// Which certificate a cell's samples make worth looking for: dark where all four are mostly
/// dark, lit where all four are mostly lit; a cell whose samples span both holds both states.
fn wanted((lowest, highest): (f64, f64)) -> Wanted {
    Wanted { dark: highest < 0.5, lit: lowest > 0.5 }
}

/// The refined steps left to the refinement ([`super::refine`]) and, per step, whether the
/// many-caster proofs showed it dark: such a step is not counted, but it keeps its place, so the
/// refinement counts and interpolates the others as it would without those proofs (the CSV does
/// not move with them; docs/energyplus-fidelity.md, "Proofs that move no value").
pub(super) struct ToCount {
    pub steps: Vec<Rough>,
    pub dark: Vec<bool>,
}

/// Writes the steps of `rough` that a single-caster certificate settles into `schedule` and
/// returns the rest ([`ToCount`], in their order, those the many-caster proofs showed dark
/// marked), with the numbers of steps proved dark and lit.
pub(super) fn settle(certifier: &Certifier, rough: Vec<Rough>, schedule: &mut Columns) -> (ToCount, usize, usize) {
    let mut order: Vec<usize> = (0..rough.len()).collect();
    order.sort_by_key(|&i| rough[i].cell);
    let cells: Vec<&[usize]> = order.chunk_by(|a, b| rough[*a].cell == rough[*b].cell).collect();
    let asked: Vec<(&[usize], Wanted)> = cells
        .into_iter()
        .map(|steps| (steps, wanted(rough[steps[0]].corners)))
        .filter(|(steps, w)| steps.len() >= MIN_STEPS && (w.dark || w.lit))
        .collect();
    let suns: Vec<Vec<DVec3>> = asked.iter().map(|(steps, _)| steps.iter().map(|&i| rough[i].sun).collect()).collect();
    let sets: Vec<(usize, &[DVec3], Wanted)> =
        asked.iter().zip(&suns).map(|((steps, w), s)| (rough[steps[0]].column, s.as_slice(), *w)).collect();
    let mut settled = vec![false; rough.len()];
    let mut together = vec![false; rough.len()];
    let (mut dark, mut lit) = (0, 0);
    for ((steps, _), proof) in asked.iter().zip(certifier.certify_all(&sets)) {
        let Some(Proof { certificate, alone }) = proof else { continue };
        for &i in *steps {
            if alone {
                schedule.set(rough[i].row, rough[i].column, fraction(certificate));
                settled[i] = true;
            } else {
                together[i] = true;
            }
        }
        match certificate {
            Certificate::Dark => dark += steps.len(),
            Certificate::Lit => lit += steps.len(),
        }
    }
    // The tally walks every refined step again: only when someone reads it.
    if log::log_enabled!(log::Level::Info) {
        let proved = settled.iter().zip(&together).map(|(a, b)| *a || *b);
        log::info!("certificates by rule (steps / proved): {}", tally(rough.iter().zip(proved)));
    }
    let (steps, dark_marks) = rough.into_iter().zip(settled).zip(together).filter(|((_, s), _)| !s).map(|((r, _), t)| (r, t)).unzip();
    (ToCount { steps, dark: dark_marks }, dark, lit)
}

/// Sets the refined timesteps that a certificate proves dark or lit (this module) and returns
/// the rest, to count, with the interpolated ones not proved never dark
/// ([`never_dark`]). `index`: the counting engine's own index of `scene`, shared where it has one;
/// `proofs`: [`super::annual::AnnualOptions::many_casters`] and
/// [`super::annual::AnnualOptions::inner_corners`].
#[allow(clippy::too_many_arguments)] // The year's steps and where they go; grouping them would hide nothing.
pub(super) fn certify_steps(
    scene: &Scene,
    index: Option<&ExactEngine>,
    (many_casters, inner_corners): (bool, bool),
    location: &Location,
    timesteps: Timesteps,
    rough: Vec<Rough>,
    smooth: Vec<Smooth>,
    schedule: &mut Columns,
) -> ToCount {
    let (start, cpu) = (seconds(), cpu_seconds());
    let certifier = match index {
        Some(index) => Certifier::sharing(scene, index),
        None => Certifier::new(scene),
    };
    let certifier = if many_casters { certifier.with_many_casters() } else { certifier };
    let certifier = if many_casters && inner_corners { certifier.with_inner_corners() } else { certifier };
    let asked = rough.len();
    let (mut rest, dark, lit) = settle(&certifier, rough, schedule);
    let interpolated = smooth.len();
    let sun_of = |row: usize| {
        let instant = timesteps.instant(row);
        (sun_direction(location, shading_sun_day(instant.day), instant.hour), f64::from(instant.day))
    };
    let unproved = never_dark(&certifier, smooth, &sun_of);
    // Without the never-dark proof no interpolated step is handed over: say nothing of them then.
    let proof = if interpolated == 0 {
        String::new()
    } else {
        format!("; of {interpolated} interpolated, {} not proved never dark", unproved.len())
    };
    log::info!(
        "refinement: {asked} timesteps to count, {dark} proved dark and {lit} proved lit{proof}; {} counted \
         (certificates {:.1} s, {:.1} s CPU)",
        rest.dark.iter().filter(|d| !**d).count() + unproved.len(),
        seconds() - start,
        cpu_seconds() - cpu
    );
    rest.dark.extend(std::iter::repeat_n(false, unproved.len()));
    rest.steps.extend(unproved);
    rest
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cheap interleaving is the bits' own: every day and τ index a grid can have (below
    /// 2¹⁶) against a loop over the bits, at all indices below 600 and the largest ones.
    #[test]
    fn block_order_interleaves_the_bits_of_day_and_time_of_day() {
        let slow =
            |k: u16, j: u16| (0..16).fold(0, |key, b| key | (u64::from(k >> b & 1) << (2 * b)) | (u64::from(j >> b & 1) << (2 * b + 1)));
        let edges = (0..600).chain(u16::MAX - 600..=u16::MAX);
        for k in edges.clone() {
            for j in (0..600).chain([u16::MAX - 1, u16::MAX]) {
                assert_eq!(block_order((k, j)), slow(k, j), "({k}, {j})");
            }
        }
        assert_eq!(edges.count(), 1201);
    }
}
