//! Never-dark proofs over many cells of one receiver at once. The year hands over a receiver's
//! interpolated steps cell by cell (a cell: its steps between two sample days and two
//! neighbouring samples of a day), in an order where a run's halves are blocks of days by times
//! of day (`year::certified`). Proved cell by
//! cell, blaas-louvres' year spent about 7 µs a step, where every step is proved: as much as
//! the year's counting. Here a run of neighbouring cells is proved at once, over one cone
//! holding every cell's cone, then in halves where the run is not proved, down to single cells,
//! which are proved as before ([`Certifier::bisect_not_dark`]: whole, then halves of its steps).
//!
//! Owns the tree of runs and the runs' cones. Exact as each cell's proof is: a cell's cone holds
//! each of its suns strictly inside ([`DirectionCone::enclosing`] of the steps' own sun
//! directions, so no bound on a day's arc is needed), and a run's cone is the enclosure of its
//! cells' cones' generators, so every direction of a cell's cone, a non-negative combination of
//! those generators, lies in the run's convex cone. A run whose cone cannot be built (too wide
//! for one chart, a generator behind the receiver or below the horizon) is not tried.

use glam::DVec3;

use super::never_dark::Hints;
use super::{Certifier, DirectionCone, Shape, in_front, up_and_in_front};
use crate::count::exact::engine::{parallel_chunks, worker_threads};

impl Certifier<'_> {
    /// For many receivers' interpolated steps, each given as (receiver, its suns, the index in
    /// them where each cell starts, ascending from 0), in order: the indices of the suns at
    /// which the receiver is not proved partly lit (see [`Self::not_dark`]). Natively over every
    /// core.
    pub fn unproved_lit_in_cells(&self, sets: &[(usize, &[DVec3], &[usize])]) -> Vec<Vec<usize>> {
        let threads = worker_threads().min(sets.len()).max(1);
        let answers = parallel_chunks(
            sets.len(),
            threads,
            1,
            || (),
            |i, _| {
                let (receiver, suns, starts) = sets[i];
                // Ascending, from 0: every sun is in a cell.
                let mut starts: Vec<usize> = [0].into_iter().chain(starts.iter().copied().filter(|s| *s < suns.len())).collect();
                starts.sort_unstable();
                starts.dedup();
                let (mut out, mut hints) = (Vec::new(), Hints::default());
                if let Some(shape) = self.shapes.get(receiver) {
                    self.prove_run(receiver, shape, suns, &starts, &mut hints, &mut out);
                }
                (out, [hints.proofs, hints.runs_proved + hints.runs_failed, hints.runs_proved, hints.apertures_proved])
            },
        );
        let counts = answers.iter().fold([0; 4], |s, (_, c)| [s[0] + c[0], s[1] + c[1], s[2] + c[2], s[3] + c[3]]);
        log::debug!(
            "never dark: {} proofs looked for, {} of them over runs of cells, {} runs proved, {} proofs held through an aperture",
            counts[0],
            counts[1],
            counts[2],
            counts[3]
        );
        answers.into_iter().map(|(out, _)| out).collect()
    }

    /// Pushes onto `out` the indices (into `suns`) of the suns of the run of cells starting at
    /// `starts` (the last ending at the end of `suns`) not proved partly lit: the whole run
    /// over one cone, else each half, down to single cells, then halves of a cell.
    fn prove_run(&self, receiver: usize, shape: &Shape, suns: &[DVec3], starts: &[usize], hints: &mut Hints, out: &mut Vec<usize>) {
        let Some(&first) = starts.first() else { return };
        // The casters near the receiver are looked for anew for each run and cell (and handed
        // only to a cell's halves): another season's suns pass other casters.
        hints.near = None;
        if starts.len() == 1 {
            self.bisect_not_dark(receiver, &suns[first..], first, hints, out);
            return;
        }
        // Runs are tried while they pay: not where they keep failing (a city's receivers behind
        // scrims, whose discs pass only short stretches of the sun's path).
        let cone = if hints.runs_failed > hints.runs_proved + RUNS_FAILED_AHEAD { None } else { run_cone(shape, &suns[first..]) };
        if let Some(cone) = cone {
            if self.not_dark_over(shape, &cone, hints) {
                hints.runs_proved += 1;
                return;
            }
            hints.runs_failed += 1;
        }
        let half = starts.len() / 2;
        let middle = starts[half];
        self.prove_run(receiver, shape, &suns[..middle], &starts[..half], hints, out);
        self.prove_run(receiver, shape, suns, &starts[half..], hints, out);
    }
}

/// Runs of several cells stop being tried for a receiver once this many more have failed than
/// been proved: each failure costs a proof over a wide cone on top of its cells' own.
const RUNS_FAILED_AHEAD: usize = 2;

/// One cone holding every one of a run's `suns` (see [`DirectionCone::bounding`]), where every
/// sun is up and in front of the receiver and so is the whole cone.
fn run_cone(shape: &Shape, suns: &[DVec3]) -> Option<DirectionCone> {
    if !up_and_in_front(shape, suns) {
        return None;
    }
    let cone = DirectionCone::bounding(suns)?;
    in_front(shape, &cone).then_some(cone)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::count::ViewRequest;
    use crate::count::certify::tests::{block, golden, random, window};
    use crate::count::certify::{MIN_LIT_SHARE, cone::MARGIN};
    use crate::count::exact::engine::ExactEngine;
    use crate::scene::SceneBuilder;
    use crate::sun::position::sun_direction;
    use glam::DVec2;

    /// A receiver facing `normal`: its steps every 15 minutes over `days`, in cells as the year
    /// gives them (14 days by 40 minutes of the day, in order of days, then time), and where
    /// each cell starts.
    fn year_cells(normal: DVec3, days: std::ops::Range<u32>) -> (Vec<DVec3>, Vec<usize>) {
        let mut cells: Vec<Vec<DVec3>> = Vec::new();
        for band in days.clone().step_by(14) {
            for slot in 0..24 {
                let mut cell = Vec::new();
                for day in band..(band + 14).min(days.end) {
                    for k in 0..3 {
                        let hour = 5.0 + (2.0 * f64::from(slot) + f64::from(k) * 2.0 / 3.0) / 3.0;
                        let s = sun_direction(&golden(), f64::from(day), hour);
                        if s.z >= crate::count::MIN_COS_INCIDENCE && s.dot(normal) > crate::count::MIN_COS_INCIDENCE {
                            cell.push(s);
                        }
                    }
                }
                if !cell.is_empty() {
                    cells.push(cell);
                }
            }
        }
        let starts = cells.iter().scan(0, |at, c| Some(std::mem::replace(at, *at + c.len()))).collect();
        (cells.concat(), starts)
    }

    /// Every run of neighbouring cells the proof may try (any stretch of a half-year's cells of
    /// a south and an east window) gets a cone, where it gets one, that holds each of the run's
    /// suns at least a tenth of [`MARGIN`] inside, and random convex combinations of them, with
    /// at most eight generators. A cone taken from each cell's four corner suns (its first and
    /// last days' first and last steps) misses some suns of the same runs: a day's arc bulges
    /// past its chord, so this test fails for a cone that trusts the corners.
    #[test]
    fn a_runs_cone_holds_every_sun_of_its_cells() {
        let mut next = random(5);
        let (mut runs, mut corners_missed) = (0, 0);
        for normal in [-DVec3::Y, DVec3::X] {
            let shape = Shape { points: vec![DVec3::ZERO], normal, ..Shape::default() };
            let (suns, starts) = year_cells(normal, 1..183);
            for _ in 0..300 {
                let a = (next() * starts.len() as f64) as usize;
                let b = (a + 1 + (next() * 40.0) as usize).min(starts.len());
                let end = starts.get(b).copied().unwrap_or(suns.len());
                let run = &suns[starts[a]..end];
                let Some(cone) = run_cone(&shape, run) else { continue };
                runs += 1;
                assert!(cone.generators().len() <= 8);
                for d in run {
                    let q = cone.chart(*d, 0.0).expect("in the chart");
                    for o in [DVec2::X, -DVec2::X, DVec2::Y, -DVec2::Y] {
                        assert!(cone.contains(cone.direction(q + 0.1 * MARGIN * o)), "a sun of cells {a}..{b} on the cone's edge");
                    }
                }
                for _ in 0..50 {
                    let d: DVec3 = run.iter().map(|s| *s * next().powi(8)).sum();
                    assert!(cone.contains(d));
                }
                // The corners of each cell of the run.
                let corners: Vec<DVec3> = (a..b)
                    .flat_map(|c| {
                        let cell = &suns[starts[c]..starts.get(c + 1).copied().unwrap_or(suns.len())];
                        [cell[0], cell[cell.len().min(3) - 1], cell[cell.len() - cell.len().min(3)], cell[cell.len() - 1]]
                    })
                    .collect();
                if let Some(four) = DirectionCone::enclosing(&corners) {
                    corners_missed += run.iter().filter(|d| !four.contains(**d)).count();
                }
            }
        }
        assert!(runs > 200, "only {runs} runs had a cone");
        assert!(corners_missed > 0, "the corners' cones held every sun: the test shows nothing");
    }

    /// Brute force against the exact engine, as the year asks: windows of random streets (the
    /// blocks narrow, so slots of sun pass between them), a quarter-year of steps in cells;
    /// every sun [`Certifier::unproved_lit_in_cells`] proves must find the window's fraction,
    /// counted, at least [`MIN_LIT_SHARE`]; and most steps are proved while some dark ones are
    /// left to count, so the test means something.
    #[test]
    fn suns_proved_in_runs_of_cells_are_lit_by_the_exact_engine() {
        let mut next = random(23);
        let (mut proved, mut unproved, mut dark_found) = (0, 0, 0);
        for _ in 0..3 {
            let mut b = SceneBuilder::new();
            b.add_object("test", "WIN", window(0.0, 2.0, 1.0, 2.5, 0.0), true);
            for k in 0..8 {
                let x = (next() * 60.0 - 30.0) as f32;
                let (w, h) = ((next() * 6.0 + 0.3) as f32, (next() * 25.0 + 2.0) as f32);
                b.add_object("test", &format!("B{k}"), block([x, -14.0, 0.0], [x + w, -10.0, h]), false);
            }
            let scene = b.build().expect("a street");
            let certifier = Certifier::new(&scene);
            let (suns, starts) = year_cells(-DVec3::Y, 1 + (next() * 250.0) as u32..100 + (next() * 250.0) as u32);
            let left = certifier.unproved_lit_in_cells(&[(0, &suns, &starts)]).remove(0);
            let requests: Vec<ViewRequest> = suns.iter().map(|s| ViewRequest::new(0, *s)).collect();
            for (k, f) in ExactEngine::new(&scene).fractions(&requests).into_iter().enumerate() {
                if left.contains(&k) {
                    unproved += 1;
                    dark_found += usize::from(f < 1e-5);
                } else {
                    assert!(f >= MIN_LIT_SHARE, "proved partly lit at {}: the exact engine says {f}", suns[k]);
                    proved += 1;
                }
            }
        }
        println!("{proved} suns proved partly lit in runs, {unproved} left to count ({dark_found} of them dark)");
        assert!(proved > 3 * unproved && dark_found >= 5, "{proved} proved, {unproved} left, {dark_found} dark");
    }
}
