//! EnergyPlus schedules, read as far as a shading surface's transmittance needs them: a value for
//! every timestep of a weather-file run.
//!
//! Owns the meaning of `Schedule:Constant`, `Schedule:Compact`, `Schedule:Year` with
//! `Schedule:Week:Daily`, `Schedule:Day:Hourly` and `Schedule:Day:Interval`, `Schedule:File`, and
//! `ScheduleTypeLimits`, as EnergyPlus's ScheduleManager resolves them for a weather-file run:
//! - a day's values are kept per minute (an `Until: HH:MM` value fills the minutes before HH:MM,
//!   an hourly value its hour, a file's item its `Minutes per Item`), and a timestep of N per hour
//!   takes, with `Interpolate` No, the value of its last minute (the one holding at its end, the
//!   instant EnergyPlus stamps it with); with Average the mean of its minutes; with Linear the
//!   mean of minutes ramped linearly from the previous `Until` value to this one;
//! - a day's type (its weekday, or a holiday, design day or custom day) and whether it is in
//!   daylight saving are the run's calendar's ([`super::calendar`]: the model's special days and
//!   daylight saving, and the weather file's when the RunPeriod uses them); `AllOtherDays` fills
//!   every day type a `For` of its `Through` left open.
//!
//! Only schedules that are asked for are read ([`Schedules::resolve`]), so a broken schedule no
//! shade uses is EnergyPlus's business, not sunlit's.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::calendar::{DAY_TYPE_NAMES, DAY_TYPES, MONTH_DAYS, ModelCalendar, WeatherDays, month_day};
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
    /// The mean over the timestep of values ramped between `Until` times.
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
                match self.interpolate {
                    Interpolate::No => minutes[step - 1],
                    Interpolate::Average | Interpolate::Linear => minutes.iter().sum::<f64>() / step as f64,
                }
            })
            .collect()
    }

    /// Values that hold until given minutes of the day (each after the previous; the last 1440).
    fn from_untils(untils: &[(usize, f64)], interpolate: Interpolate) -> Self {
        let mut minutes = Vec::with_capacity(DAY_MINUTES);
        let mut previous = untils.last().map_or(0.0, |u| u.1);
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
    File { values: Vec<f64>, minutes: usize, interpolate: Interpolate },
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
            Source::File { values, minutes, interpolate } => {
                let step = 60 / n;
                (0..days * 24 * n)
                    .map(|ts| {
                        let item = |minute: usize| values.get(minute / minutes).copied().unwrap_or(0.0);
                        match interpolate {
                            Interpolate::No => item((ts + 1) * step - 1),
                            _ => (ts * step..(ts + 1) * step).map(item).sum::<f64>() / step as f64,
                        }
                    })
                    .collect()
            }
        })
    }

    /// Every value the schedule can take (for range checks before a run).
    pub fn all_values(&self) -> Vec<f64> {
        match &self.source {
            Source::Constant(v) => vec![*v],
            Source::Calendar { days, .. } => days.iter().flat_map(|d| d.minutes.iter().copied()).collect(),
            Source::File { values, .. } => values.clone(),
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
const DAY_CLASSES: [&str; 2] = ["Schedule:Day:Hourly", "Schedule:Day:Interval"];
const LIMITS: &str = "ScheduleTypeLimits";
const WEEK: &str = "Schedule:Week:Daily";

impl<'a> Schedules<'a> {
    /// The schedules of `objects` (from `file`, whose folder is `dir`).
    pub fn new(file: &'a str, objects: &'a [IdfObject], dir: Option<&Path>) -> Self {
        let mut by_name: HashMap<String, Vec<&IdfObject>> = HashMap::new();
        let classes = YEAR_CLASSES.iter().chain(&DAY_CLASSES).chain(&[LIMITS, WEEK]);
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
    /// whole for a Discrete type), as EnergyPlus checks.
    fn check_limits(&self, object: &IdfObject, schedule: &Schedule) -> Result<()> {
        let name = object.field(1).trim();
        if name.is_empty() {
            return Ok(());
        }
        let Some(limits) = self.find(&[LIMITS], name) else {
            return Err(self.bad(object, format!("field 'Schedule Type Limits Name': '{name}' names no ScheduleTypeLimits in the model")));
        };
        let bound = |i: usize| limits.field(i).trim().parse::<f64>().ok();
        let (lower, upper) = (bound(1), bound(2));
        let discrete = limits.field(3).trim().eq_ignore_ascii_case("Discrete");
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
            let (key, rest) = field.split_once(':').map_or((field, ""), |(k, r)| (k.trim(), r.trim()));
            let at = i + 1;
            let bad = |why: String| self.bad(object, format!("field {at} '{field}' {why}"));
            match key.to_ascii_lowercase().as_str() {
                "" => {}
                "through" => parser.through(month_day(rest).ok_or_else(|| bad("is not Through: MM/DD".into()))?).map_err(bad)?,
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

    /// `Schedule:Year`: week schedules over date ranges that cover the year.
    fn year(&self, object: &IdfObject) -> Result<Source> {
        let mut days: Vec<Day> = Vec::new();
        let mut periods = Vec::new();
        let mut expected = 1;
        for (k, group) in object.fields.get(2..).unwrap_or(&[]).chunks(5).enumerate() {
            let at = |j: usize| group.get(j).map_or("", |s| s.trim());
            let date = |m: usize| month_day(&format!("{}/{}", at(m), at(m + 1)));
            let (Some(first), Some(last)) = (date(1), date(3)) else {
                return Err(self.bad(object, format!("week {}: its start and end dates are not months and days", k + 1)));
            };
            if first != expected || last < first {
                return Err(self.bad(object, format!("week {} ('{}') does not start the day after the previous one ends", k + 1, at(0))));
            }
            let Some(week) = self.find(&[WEEK], at(0)) else {
                return Err(self.bad(object, format!("Schedule Week Name '{}' names no Schedule:Week:Daily in the model", at(0))));
            };
            let mut types = [None; DAY_TYPES];
            for (t, slot) in types.iter_mut().enumerate() {
                *slot = Some(days.len());
                days.push(self.day(week, week.field(t + 1), DAY_TYPE_NAMES[t])?);
            }
            periods.push((last, types));
            expected = last + 1;
        }
        if expected <= 366 {
            return Err(self.bad(object, format!("its weeks end on {}, not on 12/31", date_text(expected - 1))));
        }
        Ok(Source::Calendar { days, periods })
    }

    /// A week's day schedule for one day type: `Schedule:Day:Hourly` or `Schedule:Day:Interval`.
    fn day(&self, week: &IdfObject, name: &str, day_type: &str) -> Result<Day> {
        let Some(day) = self.find(&DAY_CLASSES, name) else {
            return Err(self.bad(week, format!("field '{day_type} Schedule:Day Name': '{name}' names no Schedule:Day:Hourly or :Interval")));
        };
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

    /// `Schedule:File`: one column of a text file, `Minutes per Item` each, from 1 January 00:00.
    fn file_source(&self, object: &IdfObject) -> Result<Source> {
        let name = object.field(2).trim();
        let column = self.whole(object, 3, "Column Number", 1)?;
        let skip = self.whole(object, 4, "Rows to Skip at Top", 0)?;
        let hours = match object.field(5).trim() {
            "" => 8760,
            _ => self.whole(object, 5, "Number of Hours of Data", 8760)?,
        };
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
        let path = match &self.dir {
            Some(dir) => dir.join(name),
            None => PathBuf::from(name),
        };
        let text = std::fs::read_to_string(&path)
            .map_err(|e| self.bad(object, format!("field 'File Name': '{}' cannot be read ({e})", path.display())))?;
        let wanted = hours * 60 / minutes;
        let mut values = Vec::with_capacity(wanted);
        for (row, line) in text.lines().enumerate().skip(skip).take(wanted) {
            let cell = line.split(separator).map(str::trim).filter(|c| separator != ' ' || !c.is_empty()).nth(column - 1).unwrap_or("");
            let value = cell.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                self.bad(object, format!("'{}' line {}: column {column} '{cell}' is not a number", path.display(), row + 1))
            })?;
            values.push(value);
        }
        if values.len() < wanted {
            return Err(self.bad(
                object,
                format!("field 'File Name': '{}' is too short: {} values after {skip} skipped rows, {wanted} needed ({hours} hours of {minutes}-minute items)", path.display(), values.len()),
            ));
        }
        Ok(Source::File { values, minutes, interpolate })
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

    fn day_types(&mut self, text: &str) -> std::result::Result<(), String> {
        self.close_day()?;
        if self.through.is_none() {
            return Err("comes before any Through:".into());
        }
        let mut chosen = [false; DAY_TYPES];
        for word in text.split_whitespace() {
            let word = word.to_ascii_lowercase();
            let pick: Vec<usize> = match word.as_str() {
                "alldays" => (0..DAY_TYPES).collect(),
                "weekdays" => (1..6).collect(),
                "weekends" => vec![0, 6],
                "holiday" | "holidays" => vec![7],
                "alldesigndays" => vec![8, 9],
                "allotherdays" => (0..DAY_TYPES).filter(|&t| self.types[t].is_none()).collect(),
                _ => match DAY_TYPE_NAMES.iter().position(|n| n.eq_ignore_ascii_case(&word)) {
                    Some(t) => vec![t],
                    None => return Err(format!("'{word}' is not a day type")),
                },
            };
            for t in pick {
                chosen[t] = true;
            }
        }
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
                // A day type given twice in one period keeps its first For (EnergyPlus warns).
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
