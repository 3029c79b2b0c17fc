//! The fitted year at any instant: the annual spline surfaces of a run (one per receiver, lit
//! piece and leaf regime), kept after the schedule is filled so that a viewer can ask for every
//! receiver's fraction at any (day, hour), not only at the schedule's timesteps (a time-of-year
//! slider). The fitting is [`super::annual`]'s; this evaluates the surfaces exactly as the
//! schedule's evaluation does (the same sun, lit pieces, regime and clamp), so at a timestep's
//! instant it gives the schedule's value, except where the run counted that timestep directly
//! (refinement: a shadow edge sweeping through faster than the samples follow).

use glam::DVec3;

use crate::count::{MIN_COS_INCIDENCE, is_dark};
use crate::error::{Error, Result};
use crate::scene::Scene;
use crate::sun::location::Location;
use crate::sun::position::{lit_intervals, sun_direction};
use crate::year::annual::{DayMap, RegimeOf, fit_at, sun_is_up};
use crate::year::season::LeafCalendar;
use crate::year::spline::AnnualSpline;

/// One leaf regime's fitted surfaces: by receiver and lit piece (None where never lit).
pub(super) struct FittedSurfaces {
    pub(super) map: DayMap,
    pub(super) splines: Vec<Option<AnnualSpline>>,
}

/// A year's fitted annual surfaces, with what evaluating them needs (the site, the receivers'
/// normals and the leaf calendar).
pub struct FittedYear {
    location: Location,
    normals: Vec<DVec3>,
    calendar: LeafCalendar,
    regimes: Vec<FittedSurfaces>,
    regime_of: RegimeOf,
    days: u32,
}

impl std::fmt::Debug for FittedYear {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FittedYear").field("receivers", &self.normals.len()).field("regimes", &self.regimes.len()).finish()
    }
}

impl FittedYear {
    pub(super) fn new(
        scene: &Scene,
        location: &Location,
        calendar: LeafCalendar,
        regimes: Vec<FittedSurfaces>,
        regime_of: RegimeOf,
        days: u32,
    ) -> Self {
        let normals = scene.receivers.iter().map(|r| r.normal).collect();
        FittedYear { location: location.clone(), normals, calendar, regimes, regime_of, days }
    }

    /// Receivers, in the schedule's column order.
    pub fn receivers(&self) -> usize {
        self.normals.len()
    }

    /// Every receiver's sunlit fraction at calendar day `day` (1 ≤ day < days + 1; the fraction
    /// moves the sun's day on with the clock) and local standard `hour` (0..=24), from the fitted
    /// surfaces: exactly 0 where the sun is down or behind the surface, else the surface of the
    /// day's leaf regime and lit piece, clamped to [0, 1] and 0 under 1e-5 as the schedule. As the schedule, it uses the calendar
    /// day's sun ([`super::annual::shading_sun_day`]).
    pub fn fractions_at(&self, day: f64, hour: f64) -> Result<Vec<f64>> {
        let last = f64::from(self.days) + 1.0;
        if !(day.is_finite() && (1.0..last).contains(&day)) {
            return Err(Error::argument("day", format!("{day} is outside 1..{last} (day of year, fractional allowed)")));
        }
        if !(hour.is_finite() && (0.0..=24.0).contains(&hour)) {
            return Err(Error::argument("hour", format!("{hour} is outside 0..=24")));
        }
        let sun_day = day;
        let sun = sun_direction(&self.location, sun_day, hour);
        if !sun_is_up(sun) {
            return Ok(vec![0.0; self.normals.len()]);
        }
        let regime = &self.regimes[(self.regime_of)(self.calendar.phase(day))];
        let grid_day = regime.map.grid_day(day);
        Ok(self
            .normals
            .iter()
            .enumerate()
            .map(|(column, &normal)| self.value(regime, grid_day, column, normal, sun_day, hour, sun))
            .collect())
    }

    /// One receiver's value (see [`Self::fractions_at`]).
    #[allow(clippy::too_many_arguments)] // The instant in the forms the steps need; a struct would only rename them.
    fn value(&self, regime: &FittedSurfaces, grid_day: f64, column: usize, normal: DVec3, sun_day: f64, hour: f64, sun: DVec3) -> f64 {
        if is_dark(normal, sun) {
            return 0.0;
        }
        let pieces = lit_intervals(&self.location, normal, sun_day, MIN_COS_INCIDENCE);
        let Some((fit, tau)) = fit_at(&pieces, column, hour) else { return 0.0 };
        regime.splines[fit].as_ref().map_or(0.0, |s| super::annual::energyplus_fraction(s.eval(grid_day, tau)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::count::exact::Exact;
    use crate::export::Schedule;
    use crate::scene::{NodeVeil, SceneBuilder, SourceMesh};
    use crate::year::annual::{AnnualOptions, DEFAULT_REFINE, Method, annual_fitted_with};
    use crate::year::samples::{SamplingPlan, Timesteps};

    fn quad(b: &mut SceneBuilder, name: &str, q: [[f32; 3]; 4], receives: bool) {
        b.add_object("test", name, SourceMesh { positions: q.to_vec(), indices: vec![0, 1, 2, 0, 2, 3] }, receives);
    }

    /// A south window under an overhang, a north wall (two lit pieces in summer), an east wall,
    /// and with `leaves` a see-through leafy sheet (foliage) over a roof.
    fn scene(leaves: bool) -> Scene {
        let mut b = SceneBuilder::new();
        quad(&mut b, "SOUTH", [[0., 0., 0.], [2., 0., 0.], [2., 0., 1.5], [0., 0., 1.5]], true);
        quad(&mut b, "OVERHANG", [[-0.5, 0., 1.7], [2.5, 0., 1.7], [2.5, -1., 1.7], [-0.5, -1., 1.7]], false);
        quad(&mut b, "NORTH", [[2., 3., 0.], [0., 3., 0.], [0., 3., 2.], [2., 3., 2.]], true);
        quad(&mut b, "EAST", [[4., 0., 0.], [4., 2., 0.], [4., 2., 2.], [4., 0., 2.]], true);
        if leaves {
            quad(&mut b, "ROOF", [[6., 0., 0.], [8., 0., 0.], [8., 2., 0.], [6., 2., 0.]], true);
            b.set_node_veil(b.node_count(), NodeVeil { foliage: true, transmittance: 0.0 });
            let mut crown = SourceMesh::default();
            for k in 0..4 {
                let x = 6.0 + k as f32 * 0.5;
                let base = crown.positions.len() as u32;
                crown.positions.extend([[x, 0., 1.], [x + 0.4, 0., 1.], [x + 0.4, 2., 1.], [x, 2., 1.]]);
                crown.indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
            }
            b.add_object("test", "CROWN", crown, false);
        }
        b.build().unwrap()
    }

    fn fitted_year(scene: &Scene, refine: f64) -> (Schedule, FittedYear) {
        let location = Location::new(39.74, -105.18, -7.0).unwrap();
        let options = AnnualOptions {
            timesteps: Timesteps::new(2).unwrap(),
            method: Method::Spline(SamplingPlan::new(14, 9).unwrap()),
            refine,
            prove_never_dark: false,
            many_casters: Some(false),
            inner_corners: false,
        };
        let calendar = LeafCalendar::for_latitude(location.latitude);
        let (schedule, fitted) =
            pollster::block_on(annual_fitted_with(&Exact { scene }, scene, &location, &options, &calendar, &mut |_| Ok(()))).unwrap();
        (schedule, fitted.unwrap())
    }

    /// At the schedule's own instants the surfaces give the schedule's values (to f32) when
    /// nothing was refined, through every leaf regime; with refinement, they differ only at the
    /// few timesteps counted directly. Between instants they vary continuously.
    #[test]
    fn the_surfaces_give_the_schedule_at_its_instants() {
        for leaves in [false, true] {
            let scene = scene(leaves);
            let (schedule, fitted) = fitted_year(&scene, 1.0);
            assert_eq!(fitted.receivers(), schedule.names.len());
            let (mut checked, mut partial) = (0, 0);
            for row in (0..schedule.timesteps.rows()).step_by(7) {
                let instant = schedule.timesteps.instant(row);
                let values = fitted.fractions_at(f64::from(instant.day), instant.hour).unwrap();
                for (c, v) in values.iter().enumerate() {
                    let want = f64::from(schedule.get(row, c));
                    assert!((v - want).abs() < 1e-6, "leaves {leaves}, row {row} ({instant:?}), {}: {v} vs {want}", schedule.names[c]);
                    checked += 1;
                    partial += usize::from(want > 0.01 && want < 0.99);
                }
            }
            println!("leaves {leaves}: {checked} values checked, {partial} partly shaded");
            assert!(partial > 200, "leaves {leaves}: the check sees partial shade ({partial} of {checked})");
            // A quarter of a timestep on: between its neighbours' values, give or take the curve.
            let mid = fitted.fractions_at(172.0, 12.1).unwrap();
            let row = (171 * 24 + 12) * 2 - 1;
            for (c, v) in mid.iter().enumerate() {
                let (a, b) = (f64::from(schedule.get(row, c)), f64::from(schedule.get(row + 1, c)));
                assert!(*v >= a.min(b) - 0.05 && *v <= a.max(b) + 0.05, "{}: {v} between {a} and {b}", schedule.names[c]);
            }
        }
        let scene = scene(false);
        let (refined, fitted) = fitted_year(&scene, DEFAULT_REFINE);
        let (mut differ, mut cells) = (0, 0);
        for row in 0..refined.timesteps.rows() {
            let instant = refined.timesteps.instant(row);
            for (c, v) in fitted.fractions_at(f64::from(instant.day), instant.hour).unwrap().iter().enumerate() {
                differ += usize::from((v - f64::from(refined.get(row, c))).abs() > 1e-6);
                cells += 1;
            }
        }
        println!("default refinement: the surfaces differ from the schedule at {differ} of {cells} cells");
        // Measured 3,189 of 52,560 (6.1 %): the spread rule plus the near-dark cells
        // (annual::NEAR_DARK), which are counted directly so that dark steps are exact; the kink
        // rule (annual::KINK) adds none on this scene (the same count before and after it).
        assert!(differ > 0 && differ * 10 < cells, "refined cells {differ} of {cells}");
    }

    #[test]
    fn instants_outside_the_year_are_refused_by_name() {
        let scene = scene(false);
        let (_, fitted) = fitted_year(&scene, 1.0);
        let day = fitted.fractions_at(366.5, 12.0).unwrap_err().to_string();
        assert!(day.contains("day") && day.contains("366.5"), "{day}");
        let hour = fitted.fractions_at(100.0, 25.0).unwrap_err().to_string();
        assert!(hour.contains("hour") && hour.contains("25"), "{hour}");
        assert_eq!(fitted.fractions_at(172.0, 0.5).unwrap(), vec![0.0; 3], "night");
    }
}
