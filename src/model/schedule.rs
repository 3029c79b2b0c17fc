//! EnergyPlus schedules, read as far as a shading surface's transmittance needs them: a value for
//! every timestep of a weather-file run.
//!
//! Owns the meaning of `Schedule:Constant`, `Schedule:Compact`, `Schedule:Year` with
//! `Schedule:Week:Daily` or `Schedule:Week:Compact`, `Schedule:Day:Hourly`, `Schedule:Day:Interval`
//! and `Schedule:Day:List`, `Schedule:File`, and `ScheduleTypeLimits`, as EnergyPlus's
//! ScheduleManager resolves them for a weather-file run:
//! - a day's values are kept per minute (an `Until: HH:MM` value fills the minutes before HH:MM,
//!   an hourly value its hour, a list's or a file's item its `Minutes per Item`), and a timestep of
//!   N per hour takes, with `Interpolate` No, the value of its last minute (the one holding at its
//!   end, the instant EnergyPlus stamps it with); with Average the mean of its minutes; with Linear
//!   the value at its end of minutes ramped linearly from the previous `Until` value to this one (a
//!   list's items are not ramped: EnergyPlus 25.2 reads a `Schedule:Day:List` at Linear as at No);
//! - a day's type (its weekday, or a holiday, design day or custom day) and whether it is in
//!   daylight saving are the run's calendar's ([`super::calendar`]: the model's special days and
//!   daylight saving, and the weather file's when the RunPeriod uses them); `AllOtherDays` fills
//!   every day type a `For` of its `Through` left open.
//!
//! Only schedules that are asked for are read ([`Schedules::resolve`]), so a broken schedule no
//! shade uses is EnergyPlus's business, not sunlit's.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::calendar::{DAY_TYPE_NAMES, DAY_TYPES, DateRule, MONTH_DAYS, ModelCalendar, WeatherDays, month_day};
use super::idf::IdfObject;
use crate::error::{Error, Result};

/// Minutes in a day.
const DAY_MINUTES: usize = 24 * 60;

/// How a day's minute values become timestep values.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
enum Interpolate {
    #[default]
    /// The value holding at the timestep's end.
    No,
    /// The mean over the timestep.
    Average,
    /// Values ramped minute by minute between `Until` times, taken at the timestep's end.
    Linear,
}

impl Interpolate {
    fn parse(text: &str) -> Option<Self> {
        match text.trim().to_ascii_lowercase().as_str() {
            "" | "no" => Some(Interpolate::No),
            "average" | "yes" => Some(Interpolate::Average),
            "linear" => Some(Interpolate::Linear),
            _ => None,
        }
    }
}

/// One day's values, minute by minute.
#[derive(Debug, Clone, PartialEq)]
struct Day {
    minutes: Vec<f64>,
    interpolate: Interpolate,
}

impl Day {
    /// The value of each of the day's 24·N timesteps.
    fn timestep_values(&self, per_hour: usize) -> Vec<f64> {
        let step = 60 / per_hour;
        (0..24 * per_hour)
            .map(|ts| {
                let minutes = &self.minutes[ts * step..(ts + 1) * step];
                // EnergyPlus 25.2 takes a Linear ramp's value at the step's end, as for No (its
                // reported `Schedule Value`, tests/energyplus_schedules.rs), not the step's mean.
                match self.interpolate {
                    Interpolate::No | Interpolate::Linear => minutes[step - 1],
                    Interpolate::Average => minutes.iter().sum::<f64>() / step as f64,
                }
            })
            .collect()
    }

    /// Values that hold until given minutes of the day (each after the previous; the last 1440).
    /// A Linear day ramps each period from the previous `Until` value to its own; the first
    /// period has none before it and is flat, as in EnergyPlus.
    fn from_untils(untils: &[(usize, f64)], interpolate: Interpolate) -> Self {
        let mut minutes = Vec::with_capacity(DAY_MINUTES);
        let mut previous = untils.first().map_or(0.0, |u| u.1);
        for &(until, value) in untils {
            let start = minutes.len();
            let length = (until - start).max(1) as f64;
            while minutes.len() < until {
                let ramped = previous + (value - previous) * ((minutes.len() - start + 1) as f64 / length);
                minutes.push(if interpolate == Interpolate::Linear { ramped } else { value });
            }
            previous = value;
        }
        Self { minutes, interpolate }
    }
}

/// A schedule resolved for a year: its values by day type per period, or by timestep from a file.
#[derive(Debug, Clone, PartialEq)]
enum Source {
    /// One value all year.
    Constant(f64),
    /// Periods (last day of year of each, leap-year numbering, the last 366) with a day index
    /// per day type.
    Calendar { days: Vec<Day>, periods: Vec<(u32, [Option<usize>; DAY_TYPES])> },
    /// A column of a file, one value per item of `minutes` minutes from 1 January 00:00.
    File(FileColumn),
}

/// A `Schedule:File`'s column as EnergyPlus lays it over the year.
#[derive(Debug, Clone, PartialEq)]
struct FileColumn {
    values: Vec<f64>,
    minutes: usize,
    interpolate: Interpolate,
    /// Whether the file holds a leap year (8,784 hours of items): its days are then the
    /// leap-numbered days of the year, Feb 29 skipped in a plain run; a plain file's Feb 29, in a
    /// leap run, is its Feb 28 again (EnergyPlus's `ProcessScheduleInput`).
    leap: bool,
    /// `Adjust Schedule for Daylight Savings` (default Yes): No keeps the file in standard time.
    daylight_saving: bool,
}

impl FileColumn {
    /// The file's day (0-based) that holds the run's day `day` (0-based).
    fn file_day(&self, day: usize, leap_run: bool) -> usize {
        // Feb 29 is day 59 (0-based) of the leap numbering every schedule uses.
        let leap_day = if leap_run || day < 59 { day } else { day + 1 };
        match leap_day {
            d if self.leap || d < 59 => d,
            59 => 58,
            d => d - 1,
        }
    }

    /// The value of every timestep of a run of `days` days, `per_hour` timesteps an hour.
    fn timestep_values(&self, days: usize, per_hour: usize, leap_run: bool) -> Vec<f64> {
        let step = 60 / per_hour;
        let per_day = 24 * per_hour;
        (0..days * per_day)
            .map(|ts| {
                let first = self.file_day(ts / per_day, leap_run) * DAY_MINUTES + (ts % per_day) * step;
                let item = |minute: usize| self.values.get(minute / self.minutes).copied().unwrap_or(0.0);
                match self.interpolate {
                    Interpolate::Average => (first..first + step).map(item).sum::<f64>() / step as f64,
                    Interpolate::No | Interpolate::Linear => item(first + step - 1),
                }
            })
            .collect()
    }
}

/// A schedule as EnergyPlus would run it: see the module doc.
#[derive(Debug, Clone, PartialEq)]
pub struct Schedule {
    /// Its name as written.
    pub name: String,
    /// `Class 'Name' (line N)`, for messages.
    pub label: String,
    source: Source,
    /// The model's side of the run's calendar: weekdays, special days, daylight saving.
    calendar: ModelCalendar,
}

/// What a run needs to know about its calendar to read schedules.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunCalendar<'a> {
    /// Timesteps per hour.
    pub per_hour: u32,
    /// Whether the run has a Feb 29.
    pub leap: bool,
    /// The weather file's holidays and daylight saving period, when a weather file is given.
    pub weather: Option<&'a WeatherDays>,
}

impl Schedule {
    /// Whether the value is the same at every timestep of every day.
    pub fn constant(&self) -> Option<f64> {
        match &self.source {
            Source::Constant(v) => Some(*v),
            _ => None,
        }
    }

    /// The value of every timestep of the run, in row order (day → hour → timestep). On the days
    /// of a daylight-saving period each timestep takes the value one hour later (the first hour
    /// of the next day for the last), as EnergyPlus's `LookUpScheduleValue` adds its
    /// `DSTIndicator` to the hour. Refused for a calendar date the run's year does not have
    /// ([`ModelCalendar::day_types`]).
    pub fn values(&self, calendar: RunCalendar<'_>) -> Result<Vec<f64>> {
        let standard = self.standard_values(calendar)?;
        if matches!(&self.source, Source::File(f) if !f.daylight_saving) {
            return Ok(standard);
        }
        let saving = self.calendar.saving_days(calendar.leap, calendar.weather)?;
        let per_hour = calendar.per_hour as usize;
        let per_day = 24 * per_hour;
        let last = standard.len().saturating_sub(1);
        Ok((0..standard.len())
            .map(|row| if saving[row / per_day] { standard[(row + per_hour).min(last)] } else { standard[row] })
            .collect())
    }

    /// [`Self::values`] in standard time.
    fn standard_values(&self, calendar: RunCalendar<'_>) -> Result<Vec<f64>> {
        let n = calendar.per_hour as usize;
        let days = 365 + usize::from(calendar.leap);
        Ok(match &self.source {
            Source::Constant(v) => vec![*v; days * 24 * n],
            Source::Calendar { days: profiles, periods } => {
                let per_day: Vec<Vec<f64>> = profiles.iter().map(|d| d.timestep_values(n)).collect();
                let mut out = Vec::with_capacity(days * 24 * n);
                let day_types = self.calendar.day_types(calendar.leap, calendar.weather)?;
                for (day, &day_type) in (1..=days as u32).zip(&day_types) {
                    let leap_day = if calendar.leap || day < 60 { day } else { day + 1 };
                    let types = periods.iter().find(|(last, _)| leap_day <= *last).map(|p| p.1);
                    match types.and_then(|t| t[day_type]) {
                        Some(d) => out.extend_from_slice(&per_day[d]),
                        None => out.extend(std::iter::repeat_n(0.0, 24 * n)),
                    }
                }
                out
            }
            Source::File(column) => column.timestep_values(days, n, calendar.leap),
        })
    }

    /// Every value the schedule can take (for range checks before a run).
    pub fn all_values(&self) -> Vec<f64> {
        match &self.source {
            Source::Constant(v) => vec![*v],
            Source::Calendar { days, .. } => days.iter().flat_map(|d| d.minutes.iter().copied()).collect(),
            Source::File(column) => column.values.clone(),
        }
    }
}

/// The schedule objects of a model, by lower-case name, read on demand.
pub struct Schedules<'a> {
    file: &'a str,
    /// Schedule objects of every class read here, by lower-case name (one name may be used once
    /// per class: a week and a day schedule may share one).
    objects: HashMap<String, Vec<&'a IdfObject>>,
    /// The folder relative `Schedule:File` names are found in (None: no folder, the web).
    dir: Option<PathBuf>,
    /// Every object of the model (its calendar is read from them when a schedule is).
    all: &'a [IdfObject],
}

/// Classes a shade's `Transmittance Schedule Name` may name.
const YEAR_CLASSES: [&str; 4] = ["Schedule:Constant", "Schedule:Compact", "Schedule:Year", "Schedule:File"];
/// Classes a week's day type may name.
const DAY_CLASSES: [&str; 3] = ["Schedule:Day:Hourly", "Schedule:Day:Interval", "Schedule:Day:List"];
const LIMITS: &str = "ScheduleTypeLimits";
/// Classes a `Schedule:Year` may name for its weeks.
const WEEK_CLASSES: [&str; 2] = ["Schedule:Week:Daily", "Schedule:Week:Compact"];

impl<'a> Schedules<'a> {
    /// The schedules of `objects` (from `file`, whose folder is `dir`).
    pub fn new(file: &'a str, objects: &'a [IdfObject], dir: Option<&Path>) -> Self {
        let mut by_name: HashMap<String, Vec<&IdfObject>> = HashMap::new();
        let classes = YEAR_CLASSES.iter().chain(&DAY_CLASSES).chain(&WEEK_CLASSES).chain(&[LIMITS]);
        for o in objects.iter().filter(|o| classes.clone().any(|c| o.is(c))) {
            if let Some(n) = o.name() {
                by_name.entry(n.to_ascii_lowercase()).or_default().push(o);
            }
        }
        Self { file, objects: by_name, dir: dir.map(Path::to_path_buf), all: objects }
    }

    fn find(&self, classes: &[&str], name: &str) -> Option<&'a IdfObject> {
        self.objects.get(&name.trim().to_ascii_lowercase())?.iter().copied().find(|o| classes.iter().any(|c| o.is(c)))
    }

    /// The schedule `name`, checked against its `ScheduleTypeLimits`; `user` (an object label)
    /// and `field` name who asked for it, for the message when it does not exist.
    pub fn resolve(&self, name: &str, user: &str, field: &str) -> Result<Schedule> {
        let Some(object) = self.find(&YEAR_CLASSES, name) else {
            return Err(Error::object(self.file, user, format!("field '{field}': '{name}' names no schedule in the model")));
        };
        let source = self.source(object)?;
        // A special day or daylight saving date sunlit cannot read is refused: it would change
        // the schedule's values for days or months.
        let calendar = ModelCalendar::read(self.file, self.all)?;
        let schedule = Schedule { name: object.field(0).to_string(), label: object.label(), source, calendar };
        self.check_limits(object, &schedule)?;
        Ok(schedule)
    }

    fn bad(&self, object: &IdfObject, reason: impl Into<String>) -> Error {
        Error::object(self.file, object.label(), reason)
    }

    fn source(&self, object: &IdfObject) -> Result<Source> {
        if object.is("Schedule:Constant") {
            Ok(Source::Constant(self.number(object, 2, "Hourly Value")?))
        } else if object.is("Schedule:Compact") {
            self.compact(object)
        } else if object.is("Schedule:Year") {
            self.year(object)
        } else {
            self.file_source(object)
        }
    }

    fn number(&self, object: &IdfObject, i: usize, field: &str) -> Result<f64> {
        let text = object.field(i).trim();
        text.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| self.bad(object, format!("field '{field}': '{text}' is not a number")))
    }

    /// `ScheduleTypeLimits`: the named limits must exist, and every value lie within them (and be
    /// whole for a Discrete or Integer type), as EnergyPlus checks. Like EnergyPlus, a limits
    /// object with either bound blank limits nothing.
    fn check_limits(&self, object: &IdfObject, schedule: &Schedule) -> Result<()> {
        let name = object.field(1).trim();
        if name.is_empty() {
            return Ok(());
        }
        let Some(limits) = self.find(&[LIMITS], name) else {
            return Err(self.bad(object, format!("field 'Schedule Type Limits Name': '{name}' names no ScheduleTypeLimits in the model")));
        };
        let bound = |i: usize| limits.field(i).trim().parse::<f64>().ok();
        let (lower, upper) = match (bound(1), bound(2)) {
            (Some(l), Some(u)) => (Some(l), Some(u)),
            _ => return Ok(()),
        };
        let numeric = limits.field(3).trim();
        let discrete = numeric.eq_ignore_ascii_case("Discrete") || numeric.eq_ignore_ascii_case("Integer");
        for v in schedule.all_values() {
            let outside = lower.is_some_and(|l| v < l) || upper.is_some_and(|u| v > u);
            if outside || (discrete && v.fract() != 0.0) {
                let show = |b: Option<f64>| b.map_or(String::new(), |b| b.to_string());
                let kind = if discrete { "discrete " } else { "" };
                return Err(self.bad(
                    object,
                    format!("value {v} is outside its {kind}ScheduleTypeLimits '{name}' ({}..{})", show(lower), show(upper)),
                ));
            }
        }
        Ok(())
    }

    /// `Schedule:Compact`: `Through:` periods, each with `For:` day types, an optional
    /// `Interpolate:` and `Until:` value pairs.
    fn compact(&self, object: &IdfObject) -> Result<Source> {
        let mut parser = Compact::default();
        let mut i = 2;
        while i < object.fields.len() {
            let field = object.field(i).trim();
            let (key, rest) = keyword(field);
            let at = i + 1;
            let bad = |why: String| self.bad(object, format!("field {at} '{field}' {why}"));
            match key.as_str() {
                "" => {}
                "through" => parser
                    .through(through_day(rest).ok_or_else(|| bad("is not Through: a date (MM/DD, or a month name and a day)".into()))?)
                    .map_err(bad)?,
                "for" => parser.day_types(rest).map_err(bad)?,
                "interpolate" => {
                    let how = Interpolate::parse(rest).ok_or_else(|| bad("is not Interpolate: No, Average or Linear".into()))?;
                    parser.interpolate = how;
                }
                "until" => {
                    let until = clock(rest).ok_or_else(|| bad("is not Until: HH:MM".into()))?;
                    let value = self.number(object, i + 1, &format!("field {} (the value until {rest})", i + 2))?;
                    i += 1;
                    parser.until(until, value).map_err(bad)?;
                }
                _ => return Err(bad("is not Through:, For:, Interpolate: or Until:".into())),
            }
            i += 1;
        }
        parser.finish().map_err(|why| self.bad(object, why))
    }

    /// `Schedule:Year`: week schedules over date ranges that cover the year, in any order; a range
    /// may run over New Year, and Feb 29 left out takes Feb 28's week (as EnergyPlus does).
    fn year(&self, object: &IdfObject) -> Result<Source> {
        let mut days: Vec<Day> = Vec::new();
        // Per week schedule used: its name and its day index per day type.
        let mut weeks: Vec<(String, [Option<usize>; DAY_TYPES])> = Vec::new();
        // The week (index into `weeks`) of every leap-numbered day.
        let mut week_of: Vec<Option<usize>> = vec![None; 366];
        for (k, group) in object.fields.get(2..).unwrap_or(&[]).chunks(5).enumerate() {
            let at = |j: usize| group.get(j).map_or("", |s| s.trim());
            let date = |m: usize| month_day(&format!("{}/{}", at(m), at(m + 1)));
            let (Some(first), Some(last)) = (date(1), date(3)) else {
                return Err(self.bad(object, format!("week {}: its start and end dates are not months and days", k + 1)));
            };
            let index = match weeks.iter().position(|w| w.0.eq_ignore_ascii_case(at(0))) {
                Some(index) => index,
                None => {
                    let Some(week) = self.find(&WEEK_CLASSES, at(0)) else {
                        return Err(self.bad(
                            object,
                            format!("Schedule Week Name '{}' names no Schedule:Week:Daily or Schedule:Week:Compact in the model", at(0)),
                        ));
                    };
                    let types = if week.is("Schedule:Week:Daily") {
                        self.week_daily(week, &mut days)?
                    } else {
                        self.week_compact(week, &mut days)?
                    };
                    weeks.push((at(0).to_string(), types));
                    weeks.len() - 1
                }
            };
            let range: Vec<u32> = if first <= last { (first..=last).collect() } else { (first..=366).chain(1..=last).collect() };
            for day in range {
                let slot = &mut week_of[day as usize - 1];
                if slot.is_some() {
                    return Err(self.bad(object, format!("week {} ('{}') covers {} again", k + 1, at(0), date_text(day))));
                }
                *slot = Some(index);
            }
        }
        if week_of[59].is_none() {
            week_of[59] = week_of[58];
        }
        let mut periods: Vec<(u32, [Option<usize>; DAY_TYPES])> = Vec::new();
        for (day, week) in (1..=366).zip(&week_of) {
            let Some(week) = *week else {
                return Err(self.bad(object, format!("its weeks leave {} without a week schedule", date_text(day))));
            };
            match periods.last_mut() {
                Some((last, types)) if *types == weeks[week].1 => *last = day,
                _ => periods.push((day, weeks[week].1)),
            }
        }
        Ok(Source::Calendar { days, periods })
    }

    /// `Schedule:Week:Daily`: a day schedule per day type, in [`DAY_TYPE_NAMES`] order; pushes
    /// them to `days` and returns each type's index there.
    fn week_daily(&self, week: &IdfObject, days: &mut Vec<Day>) -> Result<[Option<usize>; DAY_TYPES]> {
        let mut types = [None; DAY_TYPES];
        for (t, slot) in types.iter_mut().enumerate() {
            *slot = Some(days.len());
            let field = format!("field '{} Schedule:Day Name'", DAY_TYPE_NAMES[t]);
            days.push(self.day(week, week.field(t + 1), &field)?);
        }
        Ok(types)
    }

    /// `Schedule:Week:Compact`: pairs of a `DayType List` (`For:` words, as in `Schedule:Compact`)
    /// and a day schedule; every day type must be given once, as EnergyPlus requires ("Missing
    /// some day assignments" and a duplicate are severe errors there). Pushes the days to `days`
    /// and returns each type's index there.
    fn week_compact(&self, week: &IdfObject, days: &mut Vec<Day>) -> Result<[Option<usize>; DAY_TYPES]> {
        let mut types = [None; DAY_TYPES];
        for (k, pair) in week.fields.get(1..).unwrap_or(&[]).chunks(2).enumerate() {
            let (list, name) = (pair[0].trim(), pair.get(1).map_or("", |n| n.trim()));
            if list.is_empty() && name.is_empty() {
                continue;
            }
            let at = 2 * k + 2;
            let given = types.map(|t| t.is_some());
            let chosen = for_day_types(list, &given, "in this week")
                .map_err(|why| self.bad(week, format!("field {at} 'DayType List {}' {why}", k + 1)))?;
            let index = days.len();
            days.push(self.day(week, name, &format!("field {} 'Schedule:Day Name {}'", at + 1, k + 1))?);
            for (slot, on) in types.iter_mut().zip(chosen) {
                if on {
                    *slot = Some(index);
                }
            }
        }
        if let Some(t) = types.iter().position(Option::is_none) {
            return Err(self.bad(week, format!("its DayType Lists give {} no day schedule (use AllOtherDays)", DAY_TYPE_NAMES[t])));
        }
        Ok(types)
    }

    /// A week's day schedule, named in `week`'s `field`: `Schedule:Day:Hourly`, `:Interval` or
    /// `:List`.
    fn day(&self, week: &IdfObject, name: &str, field: &str) -> Result<Day> {
        let Some(day) = self.find(&DAY_CLASSES, name) else {
            return Err(self.bad(week, format!("{field}: '{name}' names no Schedule:Day:Hourly, :Interval or :List")));
        };
        if day.is("Schedule:Day:List") {
            return self.day_list(day);
        }
        if day.is("Schedule:Day:Hourly") {
            let untils =
                (0..24).map(|h| Ok(((h + 1) * 60, self.number(day, h + 2, &format!("Hour {}", h + 1))?))).collect::<Result<Vec<_>>>()?;
            return Ok(Day::from_untils(&untils, Interpolate::No));
        }
        let interpolate = Interpolate::parse(day.field(2))
            .ok_or_else(|| self.bad(day, "field 'Interpolate to Timestep' is not No, Average or Linear"))?;
        let mut untils = Vec::new();
        let mut i = 3;
        while i < day.fields.len() && !day.field(i).trim().is_empty() {
            let text = day.field(i).trim();
            let text = text.strip_prefix("Until:").or_else(|| text.strip_prefix("until:")).unwrap_or(text);
            let until = clock(text).ok_or_else(|| self.bad(day, format!("field {} '{text}' is not a time HH:MM", i + 1)))?;
            untils.push((until, self.number(day, i + 1, &format!("Value Until Time {text}"))?));
            i += 2;
        }
        check_untils(&untils).map_err(|why| self.bad(day, why))?;
        Ok(Day::from_untils(&untils, interpolate))
    }

    /// `Schedule:Day:List`: a value per `Minutes per Item` minutes from midnight, exactly as many as
    /// fill the day (EnergyPlus refuses fewer or more, and minutes that do not divide an hour).
    fn day_list(&self, day: &IdfObject) -> Result<Day> {
        let interpolate = Interpolate::parse(day.field(2))
            .ok_or_else(|| self.bad(day, "field 'Interpolate to Timestep' is not No, Average or Linear"))?;
        let minutes = self.whole(day, 3, "Minutes per Item", 1)?;
        if minutes > 60 || 60 % minutes != 0 {
            return Err(self.bad(day, format!("field 'Minutes per Item': {minutes} does not divide an hour")));
        }
        let given = day.fields.len().saturating_sub(4);
        let wanted = DAY_MINUTES / minutes;
        if given != wanted {
            return Err(self.bad(day, format!("it has {given} values, and {minutes}-minute items need {wanted} to fill the day")));
        }
        let values = (0..wanted).map(|k| self.number(day, 4 + k, &format!("Value {}", k + 1))).collect::<Result<Vec<_>>>()?;
        let minutes = (0..DAY_MINUTES).map(|m| values[m / minutes]).collect();
        Ok(Day { minutes, interpolate })
    }

    /// `Schedule:File`: one column of a text file, `Minutes per Item` each, from 1 January 00:00.
    fn file_source(&self, object: &IdfObject) -> Result<Source> {
        let name = object.field(2).trim();
        let column = self.whole(object, 3, "Column Number", 1)?;
        let skip = self.whole(object, 4, "Rows to Skip at Top", 0)?;
        let hours = match object.field(5).trim() {
            "" => 8760,
            _ => self.whole(object, 5, "Number of Hours of Data", 8760)?,
        };
        if hours != 8760 && hours != 8784 {
            return Err(self.bad(object, format!("field 'Number of Hours of Data': {hours} is neither 8760 nor 8784 (a leap year)")));
        }
        let separator = match object.field(6).trim().to_ascii_lowercase().as_str() {
            "" | "comma" => ',',
            "tab" => '\t',
            "space" => ' ',
            "semicolon" => ';',
            other => return Err(self.bad(object, format!("field 'Column Separator': '{other}' is not Comma, Tab, Space or Semicolon"))),
        };
        let interpolate =
            Interpolate::parse(object.field(7)).ok_or_else(|| self.bad(object, "field 'Interpolate to Timestep' is not Yes or No"))?;
        let minutes = match object.field(8).trim() {
            "" => 60,
            _ => self.whole(object, 8, "Minutes per Item", 1)?,
        };
        if minutes == 0 || 60 % minutes != 0 {
            return Err(self.bad(object, format!("field 'Minutes per Item': {minutes} does not divide an hour")));
        }
        let daylight_saving = !object.field(9).trim().eq_ignore_ascii_case("no");
        let path = match &self.dir {
            Some(dir) => dir.join(name),
            None => PathBuf::from(name),
        };
        let text = std::fs::read_to_string(&path)
            .map_err(|e| self.bad(object, format!("field 'File Name': '{}' cannot be read ({e})", path.display())))?;
        let wanted = hours * 60 / minutes;
        // A file may hold a leap year whatever its Number of Hours says: EnergyPlus counts the
        // rows it finds, so rows past the hours asked for are read while they hold numbers.
        let leap_items = 8784 * 60 / minutes;
        let mut values = Vec::with_capacity(leap_items);
        for (row, line) in text.lines().enumerate().skip(skip).take(leap_items) {
            let cell = line.split(separator).map(str::trim).filter(|c| separator != ' ' || !c.is_empty()).nth(column - 1).unwrap_or("");
            match cell.parse::<f64>().ok().filter(|v| v.is_finite()) {
                Some(value) => values.push(value),
                None if values.len() >= wanted => break,
                None => {
                    return Err(self.bad(
                        object,
                        format!("field 'File Name': '{}' line {}: column {column} '{cell}' is not a number", path.display(), row + 1),
                    ));
                }
            }
        }
        if values.len() < wanted {
            return Err(self.bad(
                object,
                format!("field 'File Name': '{}' is too short: {} values after {skip} skipped rows, {wanted} needed ({hours} hours of {minutes}-minute items)", path.display(), values.len()),
            ));
        }
        let leap = values.len() == leap_items;
        Ok(Source::File(FileColumn { values, minutes, interpolate, leap, daylight_saving }))
    }

    fn whole(&self, object: &IdfObject, i: usize, field: &str, min: usize) -> Result<usize> {
        let text = object.field(i).trim();
        text.parse::<usize>()
            .ok()
            .filter(|v| *v >= min)
            .ok_or_else(|| self.bad(object, format!("field '{field}': '{text}' is not a whole number of at least {min}")))
    }
}

/// A `For:` being read: the day types it names, and its (minute, value) `Until:` pairs.
type OpenDay = ([bool; DAY_TYPES], Vec<(usize, f64)>);

/// `Schedule:Compact`'s state while its fields are read.
#[derive(Default)]
struct Compact {
    days: Vec<Day>,
    periods: Vec<(u32, [Option<usize>; DAY_TYPES])>,
    /// Day types of the open `For:` and the `Until:` pairs read for them.
    open: Option<OpenDay>,
    interpolate: Interpolate,
    /// The open `Through:` period's last day.
    through: Option<u32>,
    types: [Option<usize>; DAY_TYPES],
}

impl Compact {
    fn through(&mut self, last: u32) -> std::result::Result<(), String> {
        self.close_period()?;
        let previous = self.periods.last().map_or(0, |p| p.0);
        if last <= previous {
            return Err(format!("ends before the previous Through ({})", date_text(previous)));
        }
        self.through = Some(last);
        Ok(())
    }

    /// A `For:` field's day types, found as EnergyPlus's `ProcessForDayTypes` finds them: by the
    /// words its text contains (`Weekday` or `Weekdays`, `AllOtherDay`, `SummerDesignDay`, …);
    /// a day type an earlier `For:` of the period already has is refused, as EnergyPlus does.
    fn day_types(&mut self, text: &str) -> std::result::Result<(), String> {
        self.close_day()?;
        if self.through.is_none() {
            return Err("comes before any For:".into());
        }
        let chosen = for_day_types(text, &self.types.map(|t| t.is_some()), "in this Through:")?;
        self.open = Some((chosen, Vec::new()));
        self.interpolate = Interpolate::No;
        Ok(())
    }

    fn until(&mut self, until: usize, value: f64) -> std::result::Result<(), String> {
        let Some((_, untils)) = &mut self.open else { return Err("comes before any For:".into()) };
        if untils.last().is_some_and(|u| u.0 >= until) {
            return Err("is not after the previous Until:".into());
        }
        untils.push((until, value));
        Ok(())
    }

    fn close_day(&mut self) -> std::result::Result<(), String> {
        if let Some((chosen, untils)) = self.open.take() {
            check_untils(&untils)?;
            let index = self.days.len();
            self.days.push(Day::from_untils(&untils, self.interpolate));
            for (t, on) in chosen.iter().enumerate() {
                // `day_types` refused a day type given twice in one period.
                if *on && self.types[t].is_none() {
                    self.types[t] = Some(index);
                }
            }
        }
        Ok(())
    }

    fn close_period(&mut self) -> std::result::Result<(), String> {
        self.close_day()?;
        if let Some(last) = self.through.take() {
            self.periods.push((last, std::mem::take(&mut self.types)));
        }
        Ok(())
    }

    fn finish(mut self) -> std::result::Result<Source, String> {
        self.close_period()?;
        match self.periods.last() {
            Some((366, _)) => Ok(Source::Calendar { days: self.days, periods: self.periods }),
            Some((last, _)) => Err(format!("field 'Through': its dates end on {}, not on 12/31", date_text(*last))),
            None => Err("field 'Through': there is none, so no date reaches 12/31".into()),
        }
    }
}

/// The day types a `For:` field (or a week's `DayType List`) names, found as EnergyPlus's
/// `ProcessForDayTypes` finds them: by the words its text contains ([`FOR_WORDS`]: `Weekday` or
/// `Weekdays`, `SummerDesignDay`, …), then `AllOtherDay(s)` for every type not yet `given`. A day
/// type given twice (in this field or before it, `scope` saying where) is refused, as EnergyPlus
/// does.
fn for_day_types(text: &str, given: &[bool; DAY_TYPES], scope: &str) -> std::result::Result<[bool; DAY_TYPES], String> {
    let upper = text.to_ascii_uppercase();
    let mut chosen = [false; DAY_TYPES];
    let mut valid = false;
    for (word, types) in FOR_WORDS {
        if upper.contains(word) {
            for &t in types {
                if chosen[t] || given[t] {
                    return Err(format!("gives {} a second time {scope}", DAY_TYPE_NAMES[t]));
                }
                chosen[t] = true;
            }
            valid = true;
        }
    }
    if upper.contains("ALLOTHERDAY") {
        for (on, given) in chosen.iter_mut().zip(given) {
            *on |= !given;
        }
        valid = true;
    }
    if !valid {
        return Err(format!("'{text}' names no day type"));
    }
    Ok(chosen)
}

/// The words a `For:` field's day types are found by, with the day types ([`DAY_TYPE_NAMES`]
/// indices) each gives, in EnergyPlus's order; `AllOtherDays` is read after them.
const FOR_WORDS: [(&str, &[usize]); 15] = [
    ("WEEKDAY", &[1, 2, 3, 4, 5]),
    ("MONDAY", &[1]),
    ("TUESDAY", &[2]),
    ("WEDNESDAY", &[3]),
    ("THURSDAY", &[4]),
    ("FRIDAY", &[5]),
    ("WEEKEND", &[0, 6]),
    ("SATURDAY", &[6]),
    ("SUNDAY", &[0]),
    ("CUSTOMDAY1", &[10]),
    ("CUSTOMDAY2", &[11]),
    ("ALLDAY", &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]),
    ("HOLIDAY", &[7]),
    ("SUMMER", &[8]),
    ("WINTER", &[9]),
];

/// A `Schedule:Compact` field as its keyword (lower case: `through`, `for`, `interpolate`,
/// `until`; empty for a blank field) and the text after it, the colon being optional as in
/// EnergyPlus (`Through: 12/31` or `Through 12/31`).
fn keyword(field: &str) -> (String, &str) {
    let end = field.find(|c: char| !c.is_ascii_alphabetic()).unwrap_or(field.len());
    let (key, rest) = field.split_at(end);
    let rest = rest.trim_start();
    (key.to_ascii_lowercase(), rest.strip_prefix(':').unwrap_or(rest).trim())
}

/// A `Through:` date as a leap-numbered day of the year: `12/31` or a month name and a day
/// (`Dec 31`, `31 December`), as EnergyPlus's `ProcessDateString` reads it; an nth weekday of a
/// month, which EnergyPlus refuses here, is not a date.
fn through_day(text: &str) -> Option<u32> {
    match DateRule::parse(text)? {
        rule @ DateRule::Fixed(..) => rule.day(true, 0),
        DateRule::Nth(..) => None,
    }
}

/// A day's `Until` times must rise and end at 24:00.
fn check_untils(untils: &[(usize, f64)]) -> std::result::Result<(), String> {
    if untils.windows(2).any(|w| w[1].0 <= w[0].0) {
        return Err("its Until times do not rise".into());
    }
    match untils.last() {
        Some((DAY_MINUTES, _)) => Ok(()),
        _ => Err("its last Until time is not 24:00".into()),
    }
}

/// A day of the leap-numbered year as `MM/DD`.
fn date_text(day: u32) -> String {
    let mut d = day.max(1);
    for (m, len) in MONTH_DAYS.iter().enumerate() {
        if d <= *len {
            return format!("{:02}/{d:02}", m + 1);
        }
        d -= len;
    }
    "12/31".into()
}

/// `HH:MM` as minutes after midnight (1–1440).
fn clock(text: &str) -> Option<usize> {
    let (h, m) = text.trim().split_once(':')?;
    let (h, m): (usize, usize) = (h.trim().parse().ok()?, m.trim().parse().ok()?);
    let minutes = h * 60 + m;
    (m < 60 && (1..=DAY_MINUTES).contains(&minutes)).then_some(minutes)
}

#[cfg(test)]
#[path = "schedule_tests.rs"]
mod tests;
