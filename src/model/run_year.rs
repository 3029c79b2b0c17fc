//! Which calendar year a run covers, and so whether it has 366 days (8784·N rows).
//!
//! Owns the choice, in order: the year given explicitly; the EnergyPlus model's `RunPeriod`
//! Begin Year (EnergyPlus 9.0 and later; EnergyPlus runs that calendar year, Feb 29 included
//! when it is a leap year and the weather file has one, see [`choose`]); the weather file's data, when it holds a Feb 29 record (an
//! actual-year EPW of a leap year; a TMY file has none). Without any of these the year is a
//! non-leap year, as EnergyPlus's default run period.

use super::idf::IdfObject;

/// Whether `year` is a Gregorian leap year.
pub fn is_leap(year: i32) -> bool {
    (year % 4 == 0 && year % 100 != 0) || year % 400 == 0
}

/// The model's first `RunPeriod` Begin Year, if it gives one (field 4 from 9.0 on; earlier
/// versions have no year field).
pub fn run_period_year(objects: &[IdfObject]) -> Option<i32> {
    let version = super::idf::version(objects);
    let layout = super::building::IddLayout::from_version(version.as_deref());
    if layout.shading_control {
        return None;
    }
    let o = objects.iter().find(|o| o.is("RunPeriod"))?;
    o.field(3).trim().parse::<i32>().ok().filter(|y| *y > 0)
}

/// The year of an EPW's Feb 29 record (its first column), if it has one: an actual-year weather
/// file of a leap year.
pub fn epw_leap_year(text: &str) -> Option<i32> {
    text.lines().skip(8).find_map(|line| {
        let mut f = line.split(',');
        let (year, month, day) = (f.next()?, f.next()?, f.next()?);
        (month.trim() == "2" && day.trim() == "29").then(|| year.trim().parse().ok()).flatten()
    })
}

/// Where the year came from, for the message that names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum YearSource {
    /// Given explicitly.
    Given,
    /// The model's RunPeriod.
    RunPeriod,
    /// The weather file's Feb 29 record.
    Weather,
}

/// The run's year by the order above, with its source; None for the default non-leap year.
///
/// A RunPeriod in a leap year over a weather file without a Feb 29 record (any TMY file) counts
/// as no year: EnergyPlus 25.2 then runs 365 days, skips Feb 29 and numbers 1 March as day 60 for
/// its sun (measured: a 2020 RunPeriod on Chicago's TMY3 gives 35,040 rows at Timestep 4, and its
/// dark steps follow day 60 on 1 March), which is the non-leap year's schedule.
pub fn choose(given: Option<i32>, objects: Option<&[IdfObject]>, epw: Option<&str>) -> Option<(i32, YearSource)> {
    let weather_leap = epw.and_then(epw_leap_year);
    let run_period = objects.and_then(run_period_year).filter(|&y| !(is_leap(y) && epw.is_some() && weather_leap.is_none()));
    given
        .map(|y| (y, YearSource::Given))
        .or_else(|| run_period.map(|y| (y, YearSource::RunPeriod)))
        .or_else(|| weather_leap.map(|y| (y, YearSource::Weather)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::idf::parse_idf;

    #[test]
    fn leap_years_and_their_sources() {
        assert!(is_leap(2024) && is_leap(2000) && !is_leap(1900) && !is_leap(2023));
        let model = parse_idf("m.idf", "Version,25.2;\nRunPeriod,R,1,1,2020,12,31,2020;\n").unwrap();
        assert_eq!(run_period_year(&model), Some(2020));
        let no_year = parse_idf("m.idf", "Version,25.2;\nRunPeriod,R,1,1,,12,31,;\n").unwrap();
        assert_eq!(run_period_year(&no_year), None);
        // Before 9.0 field 4 is the End Month.
        let old = parse_idf("m.idf", "Version,8.4;\nRunPeriod,,1,1,12,31,UseWeatherFile;\n").unwrap();
        assert_eq!(run_period_year(&old), None);
        let header = "LOCATION\n".repeat(8);
        let epw = format!("{header}2020,2,28,24,60,x\n2020,2,29,1,60,x\n");
        assert_eq!(epw_leap_year(&epw), Some(2020));
        assert_eq!(epw_leap_year(&format!("{header}1999,2,28,24,60,x\n1999,3,1,1,60,x\n")), None);
        assert_eq!(choose(Some(2023), Some(&model), Some(&epw)), Some((2023, YearSource::Given)));
        assert_eq!(choose(None, Some(&model), Some(&epw)), Some((2020, YearSource::RunPeriod)));
        assert_eq!(choose(None, Some(&no_year), Some(&epw)), Some((2020, YearSource::Weather)));
        assert_eq!(choose(None, None, None), None);
        // A leap RunPeriod over a TMY file (no Feb 29) runs 365 days in EnergyPlus.
        let tmy = format!("{header}1986,2,28,24,60,x\n1986,3,1,1,60,x\n");
        assert_eq!(choose(None, Some(&model), Some(&tmy)), None);
        let non_leap = parse_idf("m.idf", "Version,25.2;\nRunPeriod,R,1,1,2021,12,31,2021;\n").unwrap();
        assert_eq!(choose(None, Some(&non_leap), Some(&tmy)), Some((2021, YearSource::RunPeriod)));
        assert_eq!(choose(None, Some(&model), None), Some((2020, YearSource::RunPeriod)));
    }
}
