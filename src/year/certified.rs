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
//! The refinement's spans counted step by step are proved here too ([`SpanProofs`]): a span is
//! one receiver's steps at one time of day on consecutive days, whose suns lie along a short
//! arc, so a caster covers it where none covered the whole cell.
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
use crate::year::refine;
use crate::year::samples::Timesteps;

/// A timestep the refinement counts directly unless a certificate settles it, kept small (a
/// city's year has millions: nyt-blocks' Timestep 4 year 6.4 M, which at 80 bytes in wasm32, with
/// its sun and day and the cell's samples as f64, took the page's engine 1.3 GB between the fit
/// and the refinement). Its sun and day follow from its row ([`RowSuns`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Rough {
    pub row: u32,
    pub column: u32,
    /// Its sample cell: regime, fitted piece (receiver and lit piece), cell's first day and τ.
    pub cell: (u16, u32, u16, u16),
    /// The certificate its cell's four samples make worth looking for ([`wanted`]).
    pub wanted: Wanted,
    /// The first rule that sent it to counting.
    pub rule: Rule,
}

impl Rough {
    /// Step `row` of receiver `column` in regime `regime`'s fitted piece `fit` and its sample
    /// cell `(k, j)`, whose samples lie between `corners` (lowest, highest), sent to counting
    /// by `rule`.
    pub(super) fn new(
        row: usize,
        column: usize,
        (regime, fit, k, j): (usize, usize, usize, usize),
        corners: (f64, f64),
        rule: Rule,
    ) -> Self {
        let small = |x: usize| u16::try_from(x).unwrap_or(u16::MAX);
        let cell = (small(regime), fit as u32, small(k), small(j));
        Rough { row: row as u32, column: column as u32, cell, wanted: wanted(corners), rule }
    }
}

/// The sun and the calendar day of every row of a year, so a step need not carry them: a
/// year's rows are few (35,040 at Timestep 4), its refined steps many.
pub(super) struct RowSuns {
    suns: Vec<DVec3>,
    rows_per_day: usize,
}

impl RowSuns {
    /// Every row's sun at `location` (each calendar day's own, [`shading_sun_day`]).
    pub(super) fn new(location: &Location, timesteps: Timesteps) -> Self {
        let suns = (0..timesteps.rows())
            .map(|row| timesteps.instant(row))
            .map(|at| sun_direction(location, shading_sun_day(at.day), at.hour))
            .collect();
        RowSuns { suns, rows_per_day: timesteps.rows() / timesteps.days() as usize }
    }

    /// The sun at `row`.
    pub(super) fn sun(&self, row: u32) -> DVec3 {
        self.suns[row as usize]
    }

    /// The calendar day (1-based) of `row`.
    pub(super) fn day(&self, row: u32) -> f64 {
        (row as usize / self.rows_per_day + 1) as f64
    }
}

/// Which refinement rule sent a step to counting (the first that applies, in this order), for
/// the year's tally of what each rule costs ([`tally`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Rule {
    /// Its piece is dark at every sample of the year (no fit).
    NoFit,
    /// The cell's samples differ by more than the refinement threshold.
    Spread,
    /// A sample day of the cell lacks the lit piece: a piece of day that comes and goes with the
    /// season (a north wall's minutes after sunrise near the equinoxes), whose samples on such a
    /// day are borrowed from the nearest day that has it (`annual::fill_dark`), so the fit there
    /// extrapolates. Measured on the north windows of NREL's 100-zone test file (issue 36,
    /// Chicago, Timestep 6, against counting every timestep): off by up to 0.51 on the days the
    /// piece appears, 0.14 with those cells counted, for 1.8 % more views.
    Borrowed,
    /// Its time lies beyond the day's outermost samples (the first and last 0.17 % of a lit piece
    /// at 19 a day), where the fit extrapolates towards the piece's end. There the sun grazes the
    /// surface and anything a little proud of its plane shades all of it: nyt-blocks' east window
    /// `F5_WIN_3` (sun at 38.6°) is 0.93 lit 1° of azimuth before the sun passes behind it, 0.54
    /// at 0.1°, 0 at 0.01°, after the last sample, and the fit kept a step there lit at 0.76 that
    /// is dark. A timestep falls there on few days, so counting them costs little.
    BeyondSamples,
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
    const ALL: [Rule; 9] = [
        Rule::NoFit,
        Rule::Spread,
        Rule::Borrowed,
        Rule::BeyondSamples,
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
            Rule::BeyondSamples => "beyond the outermost samples",
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

/// Steps proved per batch: bounds the suns held at once.
const SUNS_BATCH: usize = 1 << 18;

/// The interpolated steps of `smooth` whose receiver is not proved partly lit at their sun
/// (`suns` gives a row's sun), as steps to count. The steps of one receiver
/// and fitted piece are proved together, cell by cell in [`block_order`]: runs of neighbouring
/// cells at once (a half of a run is a block of days by times of day), then single cells, then
/// halves of a cell ([`Certifier::unproved_lit_in_cells`]).
pub(super) fn never_dark(certifier: &Certifier, mut smooth: Vec<Smooth>, suns: &RowSuns) -> Vec<Rough> {
    smooth.sort_unstable_by_key(|s| (s.regime, s.fit, block_order(s.at), s.row));
    let pieces: Vec<&[Smooth]> = smooth.chunk_by(|a, b| (a.regime, a.fit) == (b.regime, b.fit)).collect();
    let mut out = Vec::new();
    // Whole pieces per batch, up to about SUNS_BATCH steps.
    for batch in weighted_chunks(&pieces, |p| p.len(), SUNS_BATCH) {
        let directions: Vec<Vec<DVec3>> = batch.iter().map(|p| p.iter().map(|s| suns.sun(s.row)).collect()).collect();
        // Where each cell starts among its piece's steps.
        let starts: Vec<Vec<usize>> = batch.iter().map(|p| (0..p.len()).filter(|&i| i == 0 || p[i].at != p[i - 1].at).collect()).collect();
        let sets: Vec<(usize, &[DVec3], &[usize])> =
            batch.iter().zip(&directions).zip(&starts).map(|((p, d), c)| (p[0].column as usize, d.as_slice(), c.as_slice())).collect();
        for (piece, unproved) in batch.iter().zip(certifier.unproved_lit_in_cells(&sets)) {
            out.extend(unproved.into_iter().map(|k| {
                let s = piece[k];
                // An interpolated step's cell is lit at all four samples.
                let (cell, wanted) = ((s.regime, s.fit, s.at.0, s.at.1), Wanted { dark: false, lit: true });
                Rough { row: s.row, column: s.column, cell, wanted, rule: Rule::NotNeverDark }
            }));
        }
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
    /// Whether the many-caster proofs were used (asked for, or paid in the pilot): the
    /// refinement's span proofs come with them.
    pub many_casters: bool,
}

/// Where the caller leaves the many-caster proofs to the year, one cell in this many (every
/// `PILOT_STRIDE`-th in the cells' order, so every part of the model has its share) is proved
/// with them first, and their yield there decides them for the rest.
const PILOT_STRIDE: usize = 16;

/// The fewest steps the many-caster proofs must settle, per cell they are tried on in the
/// pilot, to be used for the rest. A try walks the cell's candidates over up to 15 cones (the
/// halvings), about what a view or two cost, and a step it settles saves at most a view; the
/// span proofs that come with them cost more where they settle less. Measured (pilot's yield,
/// then the year with them against without, paired): nyt-blocks' floors 5, 20 and 45 5.05,
/// 5.81 and 8.08 a cell (floor 5 0.807× main's CPU, quiet); canyon-slots 11.5; blaas-trees-summer's
/// south windows 2.60 (kept on there, they cost 1.055×), the whole model 0.46; blaas-louvres 0.
const MIN_PILOT_YIELD: f64 = 4.0;

/// What the many-caster proofs did in a pilot: cells they were tried on (a dark proof wanted,
/// the single-caster proofs found none) and steps they alone settled.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Pilot {
    tried: usize,
    settled: usize,
}

impl Pilot {
    /// The pilot's record of `proofs` over `asked` (the same order), proved with the
    /// many-caster proofs.
    fn of(asked: &[(&[usize], Wanted)], proofs: &[Option<Proof>]) -> Self {
        let mut pilot = Pilot::default();
        for ((steps, wanted), proof) in asked.iter().zip(proofs) {
            if !wanted.dark || proof.is_some_and(|p| p.alone) {
                continue;
            }
            pilot.tried += 1;
            if proof.is_some() {
                pilot.settled += steps.len();
            }
        }
        pilot
    }

    /// Whether the many-caster proofs paid in the pilot (where they were never tried, nothing
    /// says they would pay: the span proofs that come with them are then left off too).
    fn pays(self) -> bool {
        self.tried > 0 && self.settled as f64 >= MIN_PILOT_YIELD * self.tried as f64
    }
}

/// Proofs for every cell of `asked` (in order; `set_of` gives a cell's receiver, suns and
/// wanted certificate): with `certifier`'s own proofs where `many` says whether to combine
/// casters, else (`None`) with the many-caster proofs on a pilot of the cells first
/// ([`PILOT_STRIDE`]) and on the rest only where they paid there ([`Pilot::pays`]). The proofs
/// are exact either way, so the choice moves views, never values. Returns the proofs and
/// whether the many-caster proofs were used.
fn prove_cells(
    certifier: &Certifier,
    many: Option<bool>,
    asked: &[(&[usize], Wanted)],
    set_of: &dyn Fn(usize) -> Set,
) -> (Vec<Option<Proof>>, bool) {
    let single = certifier.single_casters();
    let chosen = |together: bool| if together && certifier.has_many_casters() { certifier } else { &single };
    let prove = |prover: &Certifier, cells: &[usize]| certify_in_batches(prover, cells, &|i| asked[i].0.len(), set_of);
    if let Some(together) = many {
        let all: Vec<usize> = (0..asked.len()).collect();
        return (prove(chosen(together), &all), together && certifier.has_many_casters());
    }
    let pilot: Vec<usize> = (0..asked.len()).step_by(PILOT_STRIDE).collect();
    let pilot_proofs = prove(certifier, &pilot);
    let pilot_asked: Vec<(&[usize], Wanted)> = pilot.iter().map(|&i| asked[i]).collect();
    let record = Pilot::of(&pilot_asked, &pilot_proofs);
    let together = certifier.has_many_casters() && record.pays();
    log::info!(
        "many-caster proofs: in a pilot of {} cells they settled {} steps in {} cells tried ({:.2} a cell): {} for the rest",
        pilot.len(),
        record.settled,
        record.tried,
        record.settled as f64 / record.tried.max(1) as f64,
        if together { "on" } else { "off" }
    );
    let rest: Vec<usize> = (0..asked.len()).filter(|i| i % PILOT_STRIDE != 0).collect();
    let rest_proofs = prove(chosen(together), &rest);
    let mut proofs = vec![None; asked.len()];
    for (i, p) in pilot.into_iter().zip(pilot_proofs).chain(rest.into_iter().zip(rest_proofs)) {
        proofs[i] = p;
    }
    (proofs, together)
}

/// A set of steps to prove: its receiver, its suns and the certificate wanted.
type Set = (usize, Vec<DVec3>, Wanted);

/// `prover`'s proofs of the sets `cells` names (`set_of` builds one, `steps` says how many
/// suns it holds), in order, built and proved about [`SUNS_BATCH`] suns at a time: a city's
/// refined steps' suns are never all held at once (nyt-blocks' 6.4 M, 150 MB in wasm32).
fn certify_in_batches(
    prover: &Certifier,
    cells: &[usize],
    steps: &dyn Fn(usize) -> usize,
    set_of: &dyn Fn(usize) -> Set,
) -> Vec<Option<Proof>> {
    let mut proofs = Vec::with_capacity(cells.len());
    for batch in weighted_chunks(cells, |&i| steps(i), SUNS_BATCH) {
        let owned: Vec<Set> = batch.iter().map(|&i| set_of(i)).collect();
        let sets: Vec<(usize, &[DVec3], Wanted)> = owned.iter().map(|(r, s, w)| (*r, s.as_slice(), *w)).collect();
        proofs.extend(prover.certify_all(&sets));
    }
    proofs
}

/// `items` cut, in order, into runs of at most `limit` in all by `weight` (a heavier item alone).
fn weighted_chunks<T>(items: &[T], weight: impl Fn(&T) -> usize, limit: usize) -> Vec<&[T]> {
    let mut chunks = Vec::new();
    let mut start = 0;
    while start < items.len() {
        let (mut end, mut sum) = (start, 0);
        while end < items.len() && (end == start || sum + weight(&items[end]) <= limit) {
            sum += weight(&items[end]);
            end += 1;
        }
        chunks.push(&items[start..end]);
        start = end;
    }
    chunks
}

/// Writes the steps of `rough` that a single-caster certificate settles into `schedule` and
/// returns the rest ([`ToCount`], in their order, those the many-caster proofs showed dark
/// marked), with the numbers of steps proved dark and lit. `suns` gives a step's sun; `many` as
/// for [`prove_cells`].
pub(super) fn settle(
    certifier: &Certifier,
    many: Option<bool>,
    mut rough: Vec<Rough>,
    suns: &RowSuns,
    schedule: &mut Columns,
) -> (ToCount, usize, usize) {
    let mut order: Vec<usize> = (0..rough.len()).collect();
    order.sort_by_key(|&i| rough[i].cell);
    let cells: Vec<&[usize]> = order.chunk_by(|a, b| rough[*a].cell == rough[*b].cell).collect();
    let asked: Vec<(&[usize], Wanted)> = cells
        .into_iter()
        .map(|steps| (steps, rough[steps[0]].wanted))
        .filter(|(steps, w)| steps.len() >= MIN_STEPS && (w.dark || w.lit))
        .collect();
    let set_of = |i: usize| {
        let (steps, wanted) = asked[i];
        (rough[steps[0]].column as usize, steps.iter().map(|&k| suns.sun(rough[k].row)).collect(), wanted)
    };
    let (proofs, many_casters) = prove_cells(certifier, many, &asked, &set_of);
    let mut settled = vec![false; rough.len()];
    let mut together = vec![false; rough.len()];
    let (mut dark, mut lit) = (0, 0);
    for ((steps, _), proof) in asked.iter().zip(proofs) {
        let Some(Proof { certificate, alone }) = proof else { continue };
        for &i in *steps {
            if alone {
                schedule.set(rough[i].row as usize, rough[i].column as usize, fraction(certificate));
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
    // Kept in place, not copied: a city's refined steps are its largest allocation here.
    let mut is_settled = settled.iter();
    rough.retain(|_| !is_settled.next().copied().unwrap_or(false));
    let dark_marks = settled.iter().zip(together).filter(|(s, _)| !**s).map(|(_, t)| t).collect();
    (ToCount { steps: rough, dark: dark_marks, many_casters }, dark, lit)
}

/// The year's certifier over the counting engine's own index of `scene` where it has one
/// (`index`; else it builds its own), with the proofs `(many_casters, inner_corners)` asks for
/// ([`super::annual::AnnualOptions::many_casters`] and
/// [`super::annual::AnnualOptions::inner_corners`]): the many-caster proofs unless they are
/// turned off (left to the year, its pilot decides them, [`prove_cells`]).
pub(super) fn certifier<'a>(
    scene: &Scene,
    index: Option<&'a ExactEngine>,
    (many_casters, inner_corners): (Option<bool>, bool),
) -> Certifier<'a> {
    let certifier = match index {
        Some(index) => Certifier::sharing(scene, index),
        None => Certifier::new(scene),
    };
    let many_casters = many_casters != Some(false);
    let certifier = if many_casters { certifier.with_many_casters() } else { certifier };
    if many_casters && inner_corners { certifier.with_inner_corners() } else { certifier }
}

/// Sets the refined timesteps that a certificate proves dark or lit (this module) and returns
/// the rest, to count, with the interpolated ones not proved never dark ([`never_dark`]). `many`
/// says whether to combine casters, or (`None`) leaves it to a pilot ([`prove_cells`]).
pub(super) fn certify_steps(
    certifier: &Certifier,
    many: Option<bool>,
    suns: &RowSuns,
    rough: Vec<Rough>,
    smooth: Vec<Smooth>,
    schedule: &mut Columns,
) -> ToCount {
    let (start, cpu) = (seconds(), cpu_seconds());
    let asked = rough.len();
    let (mut rest, dark, lit) = settle(certifier, many, rough, suns, schedule);
    let interpolated = smooth.len();
    let unproved = never_dark(certifier, smooth, suns);
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

/// Times a span's steps are halved where no certificate holds over all of them: each half's
/// suns span half the arc, so a caster that covers the receiver over one half only still
/// proves it (at most 2^(n+1) − 1 proofs a span).
const SPAN_HALVINGS: usize = 3;

/// Sets of fewer steps than this are not proved (nor halved into): on nyt-blocks' floor 5 a
/// proof over 4–7 steps saved 0.58 views, over 2–3 steps 0.20, and a proof costs about a view.
const MIN_SPAN_PROOF: usize = 8;

/// Spans proved per batch, between which the proofs' cost is weighed.
const SPAN_BATCH: usize = 32;

/// Proofs tried for a receiver before their yield there is judged.
const WARM_UP: usize = 16;

/// The fewest steps proved per proof tried, at a receiver, for the proofs to go on there: a
/// proof costs about what a view does, under a canopy more.
const MIN_YIELD: f64 = 2.0;

/// The refinement's span proofs ([`refine::SpanProver`]): the certifier's proofs over a span's
/// suns, the span halved where they fail. Exact like every certificate, so a proved step is
/// what counting it would give, and the refinement counts and interpolates the rest as before.
///
/// Whether they go on is decided receiver by receiver, by their yield: after [`WARM_UP`] proofs
/// for a receiver, only while they have proved at least [`MIN_YIELD`] steps per proof tried
/// there. Whether a proof pays is the receiver's surroundings': behind louvres a dark step is
/// dark behind several slats at once, which no proof here takes; under a canopy a proof walks
/// thousands of leaves for a few steps; in a street of blocks one block covers a window for
/// weeks. The values are the same however soon they stop, and the rule counts proofs, not
/// seconds, so the views counted are the same from run to run too.
pub(super) struct SpanProofs<'a> {
    certifier: &'a Certifier<'a>,
    rough: &'a [Rough],
    suns: &'a RowSuns,
    /// Per receiver: proofs tried and steps proved there.
    receivers: std::cell::RefCell<std::collections::HashMap<usize, (usize, usize)>>,
    /// Over all receivers: proofs tried and steps proved.
    totals: std::cell::Cell<(usize, usize)>,
}

impl<'a> SpanProofs<'a> {
    pub(super) fn new(certifier: &'a Certifier<'a>, rough: &'a [Rough], suns: &'a RowSuns) -> Self {
        SpanProofs { certifier, rough, suns, receivers: Default::default(), totals: std::cell::Cell::new((0, 0)) }
    }

    /// Whether the proofs have paid for `receiver` so far (or are still warming up there).
    fn paying(&self, receiver: usize) -> bool {
        let (tried, proved) = self.receivers.borrow().get(&receiver).copied().unwrap_or_default();
        tried < WARM_UP || proved as f64 >= MIN_YIELD * tried as f64
    }

    /// The steps of `spans` proved, each span halved up to [`SPAN_HALVINGS`] times where a proof
    /// over it fails (halves of at least [`MIN_SPAN_PROOF`] steps), with their values.
    fn prove_batch(&self, spans: &[(&[usize], Wanted)]) -> Vec<(usize, f64)> {
        let mut proved = Vec::new();
        let mut level = spans.to_vec();
        let mut receivers = self.receivers.borrow_mut();
        for halvings_left in (0..=SPAN_HALVINGS).rev() {
            if level.is_empty() {
                break;
            }
            let receiver = |steps: &[usize]| self.rough[steps[0]].column as usize;
            let suns: Vec<Vec<DVec3>> =
                level.iter().map(|(steps, _)| steps.iter().map(|&i| self.suns.sun(self.rough[i].row)).collect()).collect();
            let sets: Vec<(usize, &[DVec3], Wanted)> =
                level.iter().zip(&suns).map(|((steps, w), s)| (receiver(steps), s.as_slice(), *w)).collect();
            let mut next = Vec::new();
            for (&(steps, wanted), proof) in level.iter().zip(self.certifier.certify_all(&sets)) {
                let ledger = receivers.entry(receiver(steps)).or_default();
                ledger.0 += 1;
                match proof {
                    Some(p) => {
                        ledger.1 += steps.len();
                        proved.extend(steps.iter().map(|&i| (i, f64::from(fraction(p.certificate)))));
                    }
                    None if halvings_left > 0 && steps.len() >= 2 * MIN_SPAN_PROOF => {
                        let (first, second) = steps.split_at(steps.len() / 2);
                        next.extend([(first, wanted), (second, wanted)]);
                    }
                    None => {}
                }
            }
            let (tried, settled) = self.totals.get();
            self.totals.set((tried + sets.len(), settled));
            level = next;
        }
        let (tried, settled) = self.totals.get();
        self.totals.set((tried, settled + proved.len()));
        proved
    }
}

impl refine::SpanProver for SpanProofs<'_> {
    fn ledger(&self) -> (usize, usize) {
        self.totals.get()
    }

    fn prove(&self, spans: &[(Vec<usize>, Wanted)]) -> Vec<(usize, f64)> {
        let mut proved = Vec::new();
        let mut batch = Vec::with_capacity(SPAN_BATCH);
        let mut spans = spans.iter().filter(|(steps, _)| steps.len() >= MIN_SPAN_PROOF).peekable();
        while spans.peek().is_some() {
            // The ledgers move only between batches: a batch's spans are judged together.
            batch.clear();
            batch.extend(
                spans
                    .by_ref()
                    .filter(|(steps, _)| self.paying(self.rough[steps[0]].column as usize))
                    .take(SPAN_BATCH)
                    .map(|(s, w)| (s.as_slice(), *w)),
            );
            proved.extend(self.prove_batch(&batch));
        }
        proved
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::count::ViewRequest;
    use crate::count::certify::tests::{block, street, window};
    use crate::scene::SceneBuilder;
    use crate::year::refine::SpanProver;

    /// A window behind a 0.1 m slot between two 12 m blocks across a 6 m street (as in
    /// tests/annual.rs' canyon of blocks): each day at one time of day, 32 days a span, the
    /// refinement's span proofs. Every step they prove dark is dark for the exact engine at
    /// its sun; they prove most dark steps; and a span through which the slot's sun passes is
    /// proved in part (its halves), its lit steps left to count.
    #[test]
    fn span_proofs_prove_a_canyon_s_dark_days_and_leave_the_slot_s_sun_to_count() {
        let mut b = SceneBuilder::new();
        b.add_object("test", "LOW", window(2.8, 3.1, 0.0, 1.0, 0.0), true);
        b.add_object("test", "BLOCK_W", block([-40.0, -16.0, 0.0], [2.95, -6.0, 12.0]), false);
        b.add_object("test", "BLOCK_E", block([3.05, -16.0, 0.0], [40.0, -6.0, 12.0]), false);
        let scene = b.build().unwrap();
        let location = Location::new(39.74, -105.18, -7.0).unwrap();
        let index = ExactEngine::new(&scene);
        let certifier = certifier(&scene, Some(&index), (Some(true), false));
        let suns = RowSuns::new(&location, Timesteps::new(4).unwrap());
        let mut rough = Vec::new();
        let mut spans = Vec::new();
        for slot in 36..60 {
            let mut run: Vec<usize> = Vec::new();
            for day in 1..=365u32 {
                let row = (day - 1) * 96 + slot;
                let sun = suns.sun(row);
                let facing = sun.z > 0.05 && -sun.y > 0.05;
                if facing {
                    rough.push(Rough::new(row as usize, 0, (0, 0, 0, 0), (0.0, 0.0), Rule::AllNearDark));
                    run.push(rough.len() - 1);
                }
                if !facing || run.len() == 32 || day == 365 {
                    if run.len() >= 2 {
                        spans.push((std::mem::take(&mut run), Wanted { dark: true, lit: false }));
                    }
                    run.clear();
                }
            }
        }
        let proofs = SpanProofs::new(&certifier, &rough, &suns);
        let proved = proofs.prove(&spans);
        let truth = index.fractions(&rough.iter().map(|r| ViewRequest::new(0, suns.sun(r.row))).collect::<Vec<_>>());
        let mut is_proved = vec![false; rough.len()];
        for &(i, v) in &proved {
            assert_eq!(v, 0.0, "only dark was asked for");
            assert_eq!(truth[i], 0.0, "step {i} (day {}, row {}) proved dark is lit", suns.day(rough[i].row), rough[i].row);
            is_proved[i] = true;
        }
        let asked: Vec<usize> = spans.iter().flat_map(|(s, _)| s.iter().copied()).collect();
        let dark = asked.iter().filter(|&&i| truth[i] == 0.0).count();
        assert!(proved.len() * 4 >= dark * 3, "{} of {dark} dark steps proved", proved.len());
        let split = spans.iter().filter(|(s, _)| s.iter().any(|&i| truth[i] > 0.0) && s.iter().any(|&i| is_proved[i])).count();
        assert!(split > 0, "no span through the slot's sun was proved in part");
    }

    /// A street of two 30 m blocks 10 m south of a window, built flush (their faces meet at
    /// x = 1, behind the window's middle) or with a 0.3 m slot there. The sample cells are a
    /// year of one-hour blocks of 14 days around noon, dark wanted. Flush, the many-caster
    /// proofs settle the cells where neither block alone covers the window (the cover handed
    /// over, or the faces as one composite), so the pilot keeps them; with the slot the sun
    /// passes it in those cells and they settle nothing, so the pilot drops them. Either way
    /// each cell's proof is what the chosen proofs give on their own.
    #[test]
    fn the_pilot_keeps_the_many_caster_proofs_where_they_pay_and_drops_them_where_they_do_not() {
        let location = Location::new(39.74, -105.18, -7.0).unwrap();
        let mut cells: Vec<Vec<DVec3>> = Vec::new();
        for first in (1..365).step_by(14) {
            for hour in [10.0, 11.0, 12.0, 13.0] {
                let suns: Vec<DVec3> = (first..(first + 14).min(366))
                    .flat_map(|day| (0..4).map(move |q| (day, hour + 0.25 * f64::from(q))))
                    .map(|(day, h)| sun_direction(&location, f64::from(day), h))
                    .filter(|s| s.z > 0.05 && -s.y > 0.05)
                    .collect();
                if suns.len() >= 2 {
                    cells.push(suns);
                }
            }
        }
        let dark = Wanted { dark: true, lit: false };
        let steps: Vec<Vec<usize>> = cells.iter().map(|c| (0..c.len()).collect()).collect();
        let asked: Vec<(&[usize], Wanted)> = steps.iter().map(|s| (s.as_slice(), dark)).collect();
        let set_of = |i: usize| (0, cells[i].clone(), dark);
        assert!(cells.len() >= 4 * PILOT_STRIDE, "{} cells: too few for a pilot", cells.len());
        for (east_from, pays) in [(1.0, true), (1.3, false)] {
            let scene = street(east_from);
            let index = ExactEngine::new(&scene);
            let certifier = certifier(&scene, Some(&index), (None, false));
            let (proofs, kept) = prove_cells(&certifier, None, &asked, &set_of);
            assert_eq!(kept, pays, "street with its east block from x = {east_from}");

            assert_eq!(proofs, prove_cells(&certifier, Some(pays), &asked, &set_of).0, "x = {east_from}");
            let pilot: Vec<usize> = (0..cells.len()).step_by(PILOT_STRIDE).collect();
            let together = prove_cells(&certifier, Some(true), &asked, &set_of).0;
            let record =
                Pilot::of(&pilot.iter().map(|&i| asked[i]).collect::<Vec<_>>(), &pilot.iter().map(|&i| together[i]).collect::<Vec<_>>());
            assert!(record.tried > 0, "x = {east_from}: the pilot tried no cell, so it shows nothing");
            let settled = together.iter().filter(|p| p.is_some_and(|p| !p.alone)).count();
            assert_eq!(settled > 0, pays, "x = {east_from}: {settled} cells settled only by the many-caster proofs");
        }
    }

    /// A refined step stays small: a city's year holds millions of them at once (nyt-blocks'
    /// Timestep 4 year 6.4 M; at 80 bytes in wasm32 they and their copy grew the page's engine by
    /// 1.3 GB).
    #[test]
    fn a_refined_step_is_24_bytes() {
        assert!(std::mem::size_of::<Rough>() <= 24, "{} bytes", std::mem::size_of::<Rough>());
    }

    /// A row's sun and day are the ones the year evaluates that row at: the calendar day's own
    /// sun at the row's time, on every row of a Timestep 4 year and a leap year's Timestep 1.
    #[test]
    fn a_row_s_sun_is_its_calendar_day_s_at_its_time() {
        let location = Location::new(39.74, -105.18, -7.0).unwrap();
        for timesteps in [Timesteps::new(4).unwrap(), Timesteps::new(1).unwrap().leap_year(true)] {
            let suns = RowSuns::new(&location, timesteps);
            for row in 0..timesteps.rows() {
                let at = timesteps.instant(row);
                assert_eq!(suns.sun(row as u32), sun_direction(&location, shading_sun_day(at.day), at.hour), "row {row}");
                assert_eq!(suns.day(row as u32), f64::from(at.day), "row {row}");
            }
        }
    }

    /// Batches keep their items' order, hold at most the limit unless one item alone is
    /// heavier, and are never cut short of it: every item once.
    #[test]
    fn weighted_chunks_cut_in_order_up_to_the_limit() {
        let items = [3, 4, 1, 9, 2, 2, 2, 7, 1];
        let chunks = weighted_chunks(&items, |&w| w, 7);
        assert_eq!(chunks, vec![&[3, 4][..], &[1], &[9], &[2, 2, 2], &[7], &[1]]);
        assert_eq!(chunks.concat(), items);
        assert!(weighted_chunks(&[] as &[usize], |&w| w, 7).is_empty());
    }

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
