//! EnergyPlus schedules as sunlit reads them for a shade's transmittance, against the values
//! EnergyPlus 25.2 itself reports for them.
//!
//! One model holds a schedule of every form issue 36 names, written as EnergyPlus accepts them:
//! `Schedule:Constant`; `Schedule:Compact` with `Through:` dates as numbers and as month names,
//! keywords with and without their colon, `For:` day types in EnergyPlus's spellings (`Weekday`,
//! `Weekends`, `AllOtherDays`, …), and `Interpolate:` No, Average and Linear; `Schedule:Year`
//! with its weeks in any order or leaving out Feb 29, `Schedule:Week:Daily`,
//! `Schedule:Day:Hourly` and `Schedule:Day:Interval` (No, Average, Linear); `Schedule:Week:Compact`
//! (`For:` words, `AllOtherDays`) and `Schedule:Day:List` (items of 5 to 60 minutes, No, Average,
//! Linear and blank); and `Schedule:File`
//! with hourly and 10-minute items, with and without averaging, a leap (8,784-hour) and a plain
//! (8,760-hour) file, and with `Adjust Schedule for Daylight Savings` Yes and No. The model has
//! daylight saving and special days given as nth weekdays (which EnergyPlus places a day late
//! after February in a leap year), so every value is also checked for the hour daylight saving
//! moves it by and for the day types of the run's calendar.
//!
//! The reference: `Schedule Value` at every timestep (`Output:Variable, *, Schedule Value,
//! Timestep`), what EnergyPlus's `LookUpScheduleValue` gives its shading at that step, over an
//! annual run at Timestep 4 of a plain year (Chicago TMY3) and of a leap year (the same weather
//! dated 2020 with a Feb 29 added). sunlit's side is [`Schedules::resolve`] and
//! [`sunlit::model::schedule::Schedule::values`] for the same run's calendar. These never skip:
//! without EnergyPlus they fail and say how to get it.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::Scratch;
use common::energyplus::{columns, energyplus, leap_weather};
use sunlit::model::calendar::WeatherDays;
use sunlit::model::idf::parse_idf;
use sunlit::model::schedule::{RunCalendar, Schedules};

fn weather() -> PathBuf {
    energyplus().parent().unwrap().join("WeatherData/USA_IL_Chicago-OHare.Intl.AP.725300_TMY3.epw")
}

/// The schedules compared, each written as EnergyPlus 25.2 runs it without a warning.
const SCHEDULES: &str = "ScheduleTypeLimits, Fraction, 0, 1, Continuous;
Schedule:Constant, CONSTANT, Fraction, 0.2;
Schedule:Compact, C_SEASONS, Fraction,
  Through: 4/30, For: Weekdays SummerDesignDay, Until: 08:00, 0.1, Until: 18:00, 0.6, Until: 24:00, 0.3,
    For: Weekends, Until: 24:00, 0.9, For: AllOtherDays, Until: 24:00, 0.4,
  Through: 9/30, For: AllDays, Until: 24:00, 0.15,
  Through: 12/31, For: Saturday, Until: 12:00, 0.25, Until: 24:00, 0.5, For: AllOtherDays, Until: 24:00, 0.7;
Schedule:Compact, C_MONTH_NAMES, Fraction, Through: Mar 31, For: AllDays, Until: 24:00, 0.1,
  Through: 15 July, For: AllDays, Until: 24:00, 0.5, Through: December 31, For: AllDays, Until: 24:00, 0.9;
Schedule:Compact, C_NO_COLONS, Fraction, Through 12/31, For Weekday, Until 12:00, 0.3, Until 24:00, 0.6,
  For AllOtherDay, Until 24:00, 0.5;
Schedule:Compact, C_SPECIAL_DAYS, Fraction, Through: 12/31, For: Holiday, Until: 24:00, 0.9,
  For: CustomDay1, Until: 24:00, 0.6, For: CustomDay2, Until: 24:00, 0.3, For: AllOtherDays, Until: 24:00, 0.1;
Schedule:Compact, C_AVERAGE, Fraction, Through: 12/31, For: AllDays, Interpolate: Average,
  Until: 06:10, 0.2, Until: 18:50, 0.8, Until: 24:00, 0.4;
Schedule:Compact, C_LINEAR, Fraction, Through: 12/31, For: AllDays, Interpolate: Linear,
  Until: 06:00, 0.2, Until: 12:00, 0.8, Until: 24:00, 0.4;
Schedule:Year, Y_ANY_ORDER, Fraction, W_LINEAR, 7, 1, 12, 31, W_HOURLY, 1, 1, 6, 30;
Schedule:Year, Y_NO_FEB29, Fraction, W_HOURLY, 1, 1, 2, 28, W_AVERAGE, 3, 1, 12, 31;
Schedule:Week:Daily, W_HOURLY, D_HOURLY, D_HOURLY, D_HOURLY, D_HOURLY, D_HOURLY, D_HOURLY, D_AVERAGE,
  D_HOURLY, D_HOURLY, D_HOURLY, D_HOURLY, D_HOURLY;
Schedule:Week:Daily, W_LINEAR, D_LINEAR, D_LINEAR, D_LINEAR, D_LINEAR, D_LINEAR, D_LINEAR, D_LINEAR,
  D_LINEAR, D_LINEAR, D_LINEAR, D_LINEAR, D_LINEAR;
Schedule:Week:Daily, W_AVERAGE, D_AVERAGE, D_AVERAGE, D_AVERAGE, D_AVERAGE, D_AVERAGE, D_AVERAGE, D_AVERAGE,
  D_AVERAGE, D_AVERAGE, D_AVERAGE, D_AVERAGE, D_AVERAGE;
Schedule:Day:Hourly, D_HOURLY, Fraction, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7,
  0.8, 0.9, 1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1;
Schedule:Day:Interval, D_LINEAR, Fraction, Linear, 06:00, 0.2, 12:00, 0.8, 24:00, 0.4;
Schedule:Day:Interval, D_AVERAGE, Fraction, Average, 07:05, 0.3, 16:40, 0.9, 24:00, 0.0;
Schedule:File, F_PLAIN, Fraction, plain.csv, 2, 1, 8760, Comma, No, 60, Yes;
Schedule:File, F_LEAP, Fraction, leap.csv, 2, 1, 8784, Comma, No, 60, Yes;
Schedule:File, F_NO_DST, Fraction, plain.csv, 2, 1, 8760, Comma, No, 60, No;
Schedule:File, F_TEN_AVERAGE, Fraction, ten.csv, 1, 0, 8760, Semicolon, Yes, 10;
Schedule:File, F_TEN_NO, Fraction, ten.csv, 1, 0, 8760, Semicolon, No, 10;
";

/// `Schedule:Week:Compact` and `Schedule:Day:List`, their values generated ([`list_schedules`]).
const LIST_SCHEDULES: &str = "Schedule:Year, Y_WEEK_COMPACT, Fraction, W_COMPACT, 1, 1, 6, 30, W_COMPACT_ALL, 7, 1, 12, 31;
Schedule:Week:Compact, W_COMPACT, For: Weekdays, D_LIST_HOURS, For: Weekends Holiday, D_LIST_AVERAGE,
  For: AllOtherDays, D_LIST_LINEAR;
Schedule:Week:Compact, W_COMPACT_ALL, AllDays, D_LIST_QUARTERS;
Schedule:Year, Y_DAILY_LIST, Fraction, W_DAILY_LIST, 1, 1, 12, 31;
Schedule:Week:Daily, W_DAILY_LIST, D_LIST_AVERAGE, D_LIST_HOURS, D_LIST_HOURS, D_LIST_HOURS, D_LIST_HOURS, D_LIST_HOURS,
  D_LIST_AVERAGE, D_LIST_LINEAR, D_LIST_LINEAR, D_LIST_LINEAR, D_LIST_QUARTERS, D_LIST_QUARTERS;
";

/// The `Schedule:Day:List`s [`LIST_SCHEDULES`] names: hourly items (No), 10-minute items
/// (Average), 5-minute items (Linear) and 15-minute items (Interpolate blank), each value unlike
/// its neighbours so that a misplaced item shows.
fn list_schedules() -> String {
    let list = |name: &str, how: &str, minutes: usize, value: &dyn Fn(usize) -> f64| {
        let values: Vec<String> = (0..1440 / minutes).map(|k| format!("{:.4}", value(k))).collect();
        format!("Schedule:Day:List, {name}, Fraction, {how}, {minutes}, {};\n", values.join(", "))
    };
    let mut out = LIST_SCHEDULES.to_string();
    out += &list("D_LIST_HOURS", "No", 60, &|k| ((k * 7) % 20) as f64 / 20.0);
    out += &list("D_LIST_AVERAGE", "Average", 10, &|k| ((k * 13) % 21) as f64 / 20.0);
    out += &list("D_LIST_LINEAR", "Linear", 5, &|k| ((k * 7) % 23) as f64 / 22.0);
    out += &list("D_LIST_QUARTERS", "", 15, &|k| ((k * 3) % 17) as f64 / 16.0);
    out
}

/// Every schedule [`SCHEDULES`] and [`LIST_SCHEDULES`] define (the week and day schedules through
/// the years).
const NAMES: [&str; 16] = [
    "CONSTANT",
    "C_SEASONS",
    "C_SPECIAL_DAYS",
    "C_MONTH_NAMES",
    "C_NO_COLONS",
    "C_AVERAGE",
    "C_LINEAR",
    "Y_ANY_ORDER",
    "Y_NO_FEB29",
    "F_PLAIN",
    "F_LEAP",
    "F_NO_DST",
    "F_TEN_AVERAGE",
    "F_TEN_NO",
    "Y_WEEK_COMPACT",
    "Y_DAILY_LIST",
];

/// The model: a bare box (EnergyPlus needs surfaces to run), Timestep 4, daylight saving, the
/// schedules and their reported values; `year` for an actual-year RunPeriod.
fn model(year: &str) -> String {
    let mut idf = format!(
        "Version, 25.2;\nSimulationControl, No, No, No, No, Yes, No, 1;\nBuilding, MODEL, 0, Suburbs, 0.04, 0.4, FullExterior, 25, 6;\n\
         Timestep, 4;\nGlobalGeometryRules, UpperLeftCorner, Counterclockwise, World;\n\
         Site:Location, CHICAGO, 41.98, -87.92, -6, 201;\n\
         RunPeriod, YEAR, 1, 1, {year}, 12, 31, {year}, , No, No, No, Yes, Yes, No;\n\
         RunPeriodControl:DaylightSavingTime, 2nd Sunday in March, 1st Sunday in November;\n\
         RunPeriodControl:SpecialDays, FEST, 2nd Monday in March, 1, Holiday;\n\
         RunPeriodControl:SpecialDays, LAST_SUNDAY, Last Sunday in October, 1, CustomDay1;\n\
         RunPeriodControl:SpecialDays, FIRST_TUESDAY, 1st Tuesday in February, 1, CustomDay2;\n\
         Material:NoMass, INSULATION, MediumRough, 3.0, 0.9, 0.6, 0.6;\nConstruction, OPAQUE, INSULATION;\nZone, BOX;\n\
         Output:Variable, *, Schedule Value, Timestep;\n{SCHEDULES}{}",
        list_schedules()
    );
    let faces: [(&str, &str, &str, &str); 6] = [
        ("S", "Wall", "Outdoors", "0,0,3, 0,0,0, 6,0,0, 6,0,3"),
        ("E", "Wall", "Outdoors", "6,0,3, 6,0,0, 6,5,0, 6,5,3"),
        ("N", "Wall", "Outdoors", "6,5,3, 6,5,0, 0,5,0, 0,5,3"),
        ("W", "Wall", "Outdoors", "0,5,3, 0,5,0, 0,0,0, 0,0,3"),
        ("ROOF", "Roof", "Outdoors", "0,5,3, 0,0,3, 6,0,3, 6,5,3"),
        ("FLOOR", "Floor", "Ground", "0,0,0, 0,5,0, 6,5,0, 6,0,0"),
    ];
    for (name, kind, boundary, vertices) in faces {
        let sun = if boundary == "Outdoors" { "SunExposed, WindExposed" } else { "NoSun, NoWind" };
        let _ =
            writeln!(idf, "BuildingSurface:Detailed, {name}, {kind}, OPAQUE, BOX, , {boundary}, , {sun}, autocalculate, 4, {vertices};");
    }
    idf
}

/// The files the `Schedule:File`s read: a plain and a leap year of hourly values after a header
/// row (column 2), and a year of 10-minute values (column 1). Every value differs from the
/// previous day's at the same hour, so a day read out of place shows.
fn write_files(dir: &Path) {
    let hourly = |hours: usize| -> String {
        let rows: Vec<String> = (0..hours).map(|h| format!("{},{:.2}", h / 24 + 1, (h % 97) as f64 / 100.0)).collect();
        format!("day,value\n{}\n", rows.join("\n"))
    };
    std::fs::write(dir.join("plain.csv"), hourly(8760)).unwrap();
    std::fs::write(dir.join("leap.csv"), hourly(8784)).unwrap();
    let ten: Vec<String> = (0..8760 * 6).map(|i| format!("{:.2};x", (i % 13) as f64 / 20.0)).collect();
    std::fs::write(dir.join("ten.csv"), ten.join("\n") + "\n").unwrap();
}

/// Runs EnergyPlus on `idf` with `epw` into `out`, checking it ran without a warning about a
/// schedule or any severe error.
fn run_energyplus(idf: &Path, epw: &Path, out: &Path) {
    let status = Command::new(energyplus()).arg("-r").arg("-w").arg(epw).arg("-d").arg(out).arg(idf).output().unwrap();
    let err = std::fs::read_to_string(out.join("eplusout.err")).unwrap_or_default();
    let schedule_warning = |l: &str| l.contains("** Warning **") && l.to_ascii_lowercase().contains("schedule");
    let refused = err.lines().filter(|l| l.contains("** Severe  **") || l.contains("**  Fatal  **") || schedule_warning(l)).count();
    assert!(status.status.success() && refused == 0, "EnergyPlus on {}:\n{err}", idf.display());
}

/// Every schedule's values in sunlit against EnergyPlus's reported `Schedule Value`, step by
/// step; returns the schedules that differ, each with its first differing step and both values.
fn compare(dir: &Path, idf: &Path, epw: &Path, leap: bool) -> Vec<String> {
    let reported = columns(&dir.join("run").join("eplusout.csv"));
    let text = std::fs::read_to_string(idf).unwrap();
    let objects = parse_idf("schedules.idf", &text).unwrap();
    let schedules = Schedules::new("schedules.idf", &objects, Some(dir));
    let days = WeatherDays::from_epw_text("weather", &std::fs::read_to_string(epw).unwrap()).unwrap();
    let calendar = RunCalendar { per_hour: 4, leap, weather: Some(&days) };
    let mut differ = Vec::new();
    for name in NAMES {
        let theirs = &reported[&format!("{name}:SCHEDULE VALUE [](TIMESTEP)")];
        let ours = match schedules.resolve(name, "the test", "Schedule Name").and_then(|s| s.values(calendar)) {
            Ok(v) => v,
            Err(e) => {
                differ.push(format!("{name}: refused: {e}"));
                continue;
            }
        };
        assert_eq!(ours.len(), theirs.len(), "{name}: timesteps");
        let wrong: Vec<usize> = (0..ours.len()).filter(|&i| (ours[i] - theirs[i]).abs() > 1e-9).collect();
        println!("{name}: {} of {} steps differ", wrong.len(), ours.len());
        if let Some(&i) = wrong.first() {
            differ.push(format!(
                "{name}: {} steps differ, first row {i} (day {}, step {}): sunlit {} EnergyPlus {}",
                wrong.len(),
                i / 96 + 1,
                i % 96,
                ours[i],
                theirs[i]
            ));
        }
    }
    differ
}

/// A plain year (Chicago TMY3, 365 days) and a leap year (the same weather as 2020, 366 days):
/// every schedule's value at every timestep equals EnergyPlus's own to 1e-9.
#[test]
fn every_schedule_form_matches_energyplus_step_by_step() {
    let dir = Scratch::new("epschedules", "forms");
    write_files(&dir);
    let leap_epw = leap_weather(&weather(), &dir);
    let mut differ = Vec::new();
    for (label, year, epw, leap) in [("plain year", "", weather(), false), ("leap year 2020", "2020", leap_epw, true)] {
        let idf = dir.join("schedules.idf");
        std::fs::write(&idf, model(year)).unwrap();
        let _ = std::fs::remove_dir_all(dir.join("run"));
        run_energyplus(&idf, &epw, &dir.join("run"));
        println!("{label}:");
        differ.extend(compare(&dir, &idf, &epw, leap).into_iter().map(|d| format!("{label}: {d}")));
    }
    assert!(differ.is_empty(), "schedules that differ from EnergyPlus 25.2:\n{}", differ.join("\n"));
}
