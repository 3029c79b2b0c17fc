//! Shades that let part of the sun through (an EnergyPlus shade's transmittance schedule): the
//! year counted with each such shade opaque and removed, mixed per timestep.
//!
//! Owns the rule that makes a time-varying τ exact without a view per timestep and τ. EnergyPlus's
//! clipping counts a shade's shadow as (1 − τ) of it and multiplies the τ of overlapping shadows,
//! so a receiver's sunlit fraction is multilinear in the shades' τ: with k shades (or groups of
//! shades sharing a schedule) varying, f(t) = Σ_S Π_{g∈S} τ_g(t) · Π_{g∉S} (1 − τ_g(t)) · f_S(t),
//! f_S being the fraction with the groups in S removed and the others opaque. Each f_S is a static
//! scene's year, as smooth in time as any (the spline and its refinements apply unchanged), and the
//! schedule's steps (an hourly screen, a seasonal tree) enter only through the weights. So 2^k
//! years are counted. A shade whose τ is constant but between 0 and 1 is mixed too: the exact
//! engine's boundary step counts a see-through caster as opaque and the GPU's per-pixel threshold
//! is a dithered estimate, while a mix of two years of opaque or absent casters is exact on
//! either engine. Shades always at τ = 0 are plain casters and those always at 1 are left out
//! ([`crate::model::shades::ShadeGroup::constant`]). Under EnergyPlus's `Periodic` update a
//! period takes the τ of its first day ([`transmittance_row`]), as EnergyPlus's shading does.

use crate::error::{Error, Result};
use crate::export::Schedule;
use crate::model::calendar::WeatherDays;
use crate::model::schedule::RunCalendar;
use crate::model::shades::ShadeGroup;
use crate::sun::periods::ShadingPeriods;
use crate::year::annual::energyplus_fraction;
use crate::year::samples::Timesteps;

/// At most this many shade groups may be mixed: each doubles the years counted.
pub const MAX_VARYING: usize = 4;

/// The shades that are mixed, with τ per timestep.
#[derive(Debug, Clone, PartialEq)]
pub struct VaryingShades {
    /// Per group: its shades' names and its τ at every row.
    groups: Vec<(Vec<String>, Vec<f64>)>,
}

impl VaryingShades {
    /// The groups of `shades` that let part of the sun through at some time; refused past
    /// [`MAX_VARYING`] groups. None when every shade is opaque or absent all year (the scene as
    /// loaded is then already right).
    pub fn new(file: &str, shades: &[ShadeGroup], calendar: RunCalendar<'_>) -> Result<Option<Self>> {
        let mixed: Vec<&ShadeGroup> = shades.iter().filter(|g| !matches!(g.constant(), Some(t) if t == 0.0 || t >= 1.0)).collect();
        let groups: Vec<(Vec<String>, Vec<f64>)> =
            mixed.iter().map(|g| Ok((g.shades.clone(), g.values(calendar)?))).collect::<Result<_>>()?;
        if groups.len() > MAX_VARYING {
            let names: Vec<&str> = mixed.iter().map(|g| g.schedule.name.as_str()).collect();
            return Err(Error::model(
                file,
                format!(
                    "{} transmittance schedules let part of the sun through ({}); each doubles the years sunlit counts, and at most {MAX_VARYING} may",
                    groups.len(),
                    names.join(", ")
                ),
            ));
        }
        Ok((!groups.is_empty()).then_some(Self { groups }))
    }

    /// [`Self::new`] over a run's calendar: its timesteps, its leap day and the weather file's
    /// holidays and daylight saving period (when given), which the model's special days and
    /// daylight saving join. Both edges read the shades of a year this way, so the page's
    /// one-scene passes see the same τ as the CLI's.
    pub fn for_run(file: &str, shades: &[ShadeGroup], timesteps: Timesteps, weather: Option<&WeatherDays>) -> Result<Option<Self>> {
        Self::new(file, shades, RunCalendar { per_hour: timesteps.per_hour(), leap: timesteps.is_leap(), weather })
    }

    /// How many years are counted: 2^k.
    pub fn variants(&self) -> usize {
        1 << self.groups.len()
    }

    /// The shades' τ in variant `v` (bit g set: group g removed, τ = 1; clear: opaque, τ = 0),
    /// as [`crate::model::LoadOptions::shade_transmittance`] takes them.
    pub fn shade_transmittance(&self, v: usize) -> Vec<(String, f64)> {
        let mut out = Vec::new();
        for (g, (shades, _)) in self.groups.iter().enumerate() {
            let t = if v >> g & 1 == 1 { 1.0 } else { 0.0 };
            out.extend(shades.iter().map(|s| (s.clone(), t)));
        }
        out
    }

    /// Variant `v`'s weight at `row`.
    fn weight(&self, v: usize, row: usize) -> f64 {
        self.groups.iter().enumerate().map(|(g, (_, t))| if v >> g & 1 == 1 { t[row] } else { 1.0 - t[row] }).product()
    }

    /// Every variant's year (in variant order, the same columns and rows) mixed per timestep.
    pub fn mix(&self, years: &[Schedule]) -> Result<Schedule> {
        let Some(first) = years.first().filter(|_| years.len() == self.variants()) else {
            return Err(Error::argument("years", format!("{} years for {} variants", years.len(), self.variants())));
        };
        if years.iter().any(|y| y.names != first.names || y.values.len() != first.values.len()) {
            return Err(Error::argument("years", "the variants' years differ in columns or rows"));
        }
        let columns = first.names.len();
        let values = vec![0.0; first.values.len()];
        let mut out = Schedule { names: first.names.clone(), timesteps: first.timesteps, values, periods: first.periods };
        for (row, values) in out.values.chunks_mut(columns.max(1)).enumerate() {
            let at = transmittance_row(first.periods, first.timesteps, row);
            let weights: Vec<f64> = (0..years.len()).map(|v| self.weight(v, at)).collect();
            for (c, value) in values.iter_mut().enumerate() {
                let f: f64 = years.iter().zip(&weights).map(|(y, w)| w * f64::from(y.values[row * columns + c])).sum();
                *value = energyplus_fraction(f) as f32;
            }
        }
        out.validate()?;
        Ok(out)
    }

    /// Each group's mean τ over the run, for passes that take one scene (the sky views).
    pub fn mean_transmittance(&self) -> Vec<(String, f64)> {
        let mut out = Vec::new();
        for (shades, t) in &self.groups {
            let mean = t.iter().sum::<f64>() / t.len().max(1) as f64;
            out.extend(shades.iter().map(|s| (s.clone(), mean)));
        }
        out
    }
}

/// The row whose τ EnergyPlus's shading uses at `row`: the row itself, or under a `Periodic`
/// update the same timestep of the period's first day. EnergyPlus computes a period's shading on
/// that day, reading each shade's schedule at the hour and timestep of that day
/// (`LookUpScheduleValue` in SHADOW), and every day of the period reuses those fractions, so a
/// weekend screen value, say, never reaches a period that starts on a weekday.
fn transmittance_row(periods: Option<ShadingPeriods>, timesteps: Timesteps, row: usize) -> usize {
    let Some(periods) = periods else { return row };
    let per_day = timesteps.rows() / timesteps.days().max(1) as usize;
    let day = (row / per_day) as u32 + 1;
    let (start, _) = periods.period_of(day, timesteps.days());
    (start as usize - 1) * per_day + row % per_day
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::model::idf::parse_idf;
    use crate::model::shades::read_shade_schedules;

    /// Two shades, one at a constant 0.25 and one at 0 until noon and 1 after (hourly, N = 1),
    /// and a third at 0 all year (an ordinary caster, not mixed).
    fn varying() -> VaryingShades {
        let text = "Shading:Site:Detailed, A, HALF, 3, 0,0,0, 1,0,0, 1,0,1;\n\
            Shading:Site:Detailed, B, NOON, 3, 0,1,0, 1,1,0, 1,1,1;\n\
            Shading:Site:Detailed, C, ZERO, 3, 0,2,0, 1,2,0, 1,2,1;\n\
            Schedule:Constant, HALF, , 0.25;\nSchedule:Constant, ZERO, , 0;\n\
            Schedule:Compact, NOON, , Through: 12/31, For: AllDays, Until: 12:00, 0, Until: 24:00, 1;";
        let objects = parse_idf("m.idf", text).unwrap();
        let groups = read_shade_schedules("m.idf", &objects, None).unwrap();
        VaryingShades::new("m.idf", &groups, RunCalendar { per_hour: 1, leap: false, weather: None }).unwrap().unwrap()
    }

    /// Under a Periodic update every day of a period takes its first day's τ, at the same time of
    /// day; without one each row its own.
    #[test]
    fn a_period_takes_its_first_days_transmittance() {
        let t = Timesteps::new(4).unwrap();
        let periods = ShadingPeriods { days: 7, first_day: 1, run_days: 365 };
        let row = |day: usize, step: usize| (day - 1) * 96 + step;
        assert_eq!(transmittance_row(None, t, row(10, 37)), row(10, 37));
        assert_eq!(transmittance_row(Some(periods), t, row(10, 37)), row(8, 37), "days 8–14");
        assert_eq!(transmittance_row(Some(periods), t, row(7, 95)), row(1, 95), "days 1–7");
        assert_eq!(transmittance_row(Some(periods), t, row(365, 3)), row(365, 3), "the last period, one day");
    }

    /// Each group's mean τ per day of `v`'s run, to 1e-9 (a day's sum of quarter-hours rounds).
    fn daily(v: &VaryingShades, per_day: usize) -> Vec<Vec<f64>> {
        let mean = |d: &[f64]| (d.iter().sum::<f64>() / per_day as f64 * 1e9).round() / 1e9;
        v.groups.iter().map(|(_, t)| t.chunks(per_day).map(mean).collect()).collect()
    }

    /// The τ the page's one-scene passes take, read with the run's calendar (`for_run` with the
    /// weather file's text, as the page has it), is the native year's day by day on a model with
    /// a holiday of its own (25 December 2017, a Monday) and one from the weather file (4 July, a
    /// Tuesday): the holidays' τ, 0.8, where a weekday's is 0.2. The calendar the page read before
    /// (hourly, without the weather file) gave 4 July a weekday's τ, and so another mean.
    #[test]
    fn the_one_scene_transmittance_reads_the_runs_calendar() {
        let text = "RunPeriod, R, 1, 1, 2017, 12, 31, 2017, , Yes, Yes, No;\n\
            RunPeriodControl:SpecialDays, XMAS, 12/25, 1, Holiday;\n\
            Shading:Site:Detailed, SCREEN, TAU, 3, 0,0,0, 1,0,0, 1,0,1;\n\
            Schedule:Compact, TAU, , Through: 12/31, For: Weekdays, Until: 24:00, 0.2, For: AllOtherDays, Until: 24:00, 0.8;";
        let objects = parse_idf("m.idf", text).unwrap();
        let groups = read_shade_schedules("m.idf", &objects, None).unwrap();
        let epw = "LOCATION,X\nA\nB\nC\nHOLIDAYS/DAYLIGHT SAVINGS,No,0,0,1,Fest,7/4\n";
        let page_days = WeatherDays::from_epw_text("w.epw", epw).unwrap();
        let timesteps = Timesteps::new(4).unwrap();
        let page = VaryingShades::for_run("m.idf", &groups, timesteps, Some(&page_days)).unwrap().unwrap();
        // The native year: the CLI's calendar, the weather file read from its own copy.
        let native_days = WeatherDays::from_epw_text("chicago.epw", epw).unwrap();
        let calendar = RunCalendar { per_hour: 4, leap: false, weather: Some(&native_days) };
        let native = VaryingShades::new("m.idf", &groups, calendar).unwrap().unwrap();
        let (page_daily, native_daily) = (daily(&page, 96), daily(&native, 96));
        assert_eq!(page_daily, native_daily);
        let tau = &page_daily[0];
        assert_eq!(tau.len(), 365);
        assert_eq!((tau[1], tau[184], tau[358], tau[0]), (0.2, 0.8, 0.8, 0.8), "2 Jan, 4 July, 25 Dec, a Sunday");
        assert_eq!(page.mean_transmittance(), native.mean_transmittance());
        let before = VaryingShades::new("m.idf", &groups, RunCalendar { per_hour: 1, leap: false, weather: None }).unwrap().unwrap();
        assert_eq!(daily(&before, 24)[0][184], 0.2, "the page's former calendar: 4 July a weekday");
        assert!(before.mean_transmittance()[0].1 < page.mean_transmittance()[0].1);
    }

    #[test]
    fn variants_remove_each_mixed_shade_in_turn() {
        let v = varying();
        assert_eq!(v.variants(), 4, "A and B mixed, C an ordinary caster");
        assert_eq!(v.shade_transmittance(0), [("A".to_string(), 0.0), ("B".to_string(), 0.0)]);
        assert_eq!(v.shade_transmittance(3), [("A".to_string(), 1.0), ("B".to_string(), 1.0)]);
        let means = v.mean_transmittance();
        assert_eq!(means[0], ("A".to_string(), 0.25));
        assert_eq!(means[1], ("B".to_string(), 0.5));
    }

    #[test]
    fn the_mix_is_multilinear_in_the_transmittances() {
        let v = varying();
        let timesteps = Timesteps::new(1).unwrap();
        // One column: 0.1 with both opaque, 0.3 with A removed, 0.6 with B removed, 1 with both.
        let years: Vec<Schedule> = [0.1f32, 0.3, 0.6, 1.0]
            .iter()
            .map(|&f| Schedule { values: vec![f; timesteps.rows()], ..Schedule::zeros(vec!["W".into()], timesteps) })
            .collect();
        let mixed = v.mix(&years).unwrap();
        // Morning (B opaque): 0.75·0.1 + 0.25·0.3; afternoon (B removed): 0.75·0.6 + 0.25·1.
        assert!((mixed.get(5, 0) - 0.15).abs() < 1e-6, "{}", mixed.get(5, 0));
        assert!((mixed.get(17, 0) - 0.7).abs() < 1e-6, "{}", mixed.get(17, 0));
        assert!(v.mix(&years[..3]).is_err(), "one year per variant");
    }
}
