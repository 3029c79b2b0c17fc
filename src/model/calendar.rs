//! The calendar of an EnergyPlus weather-file run as its schedules see it: which day type each
//! day of the year is, and which days are in daylight saving.
//!
//! Owns, as EnergyPlus 25.2's WeatherManager sets them up (`SetSpecialDayDates`,
//! `SetDSTDateRanges`, `GetNextEnvironment`) and as measured on it (tests/energyplus_models.rs, `special_days_and_the_weather_files_calendar_match_energyplus`):
//! - the weekday of 1 January: the first RunPeriod's Begin Year's, else counted back from its
//!   `Day of Week for Start Day`, else Sunday;
//! - `RunPeriodControl:SpecialDays`: from a start date (a month and day, or the nth or last
//!   weekday of a month) for `Duration` days (1–366, wrapping over New Year), of type Holiday,
//!   SummerDesignDay, WinterDesignDay, CustomDay1 or CustomDay2;
//! - the weather file's holidays (the EPW record `HOLIDAYS/DAYLIGHT SAVINGS`), used when the
//!   RunPeriod's `Use Weather File Holidays and Special Days` is Yes (the default). EnergyPlus 25.2
//!   gives those days the day type **Sunday**, not Holiday (its eio lists them as `Sunday`, and a
//!   schedule's `For: Sunday` value holds on them, measured), and so does sunlit;
//! - the weather file's holidays come before the model's special days, and a later one
//!   overwrites an earlier one on the days they share (EnergyPlus warns);
//! - `Apply Weekend Holiday Rule` (default No): a one-day special day given as a month and day
//!   that falls on a Saturday or Sunday moves to the Monday after;
//! - daylight saving: a `RunPeriodControl:DaylightSavingTime`'s dates when the model has one
//!   (whatever the RunPeriod says), else the weather file's period when the RunPeriod's `Use
//!   Weather File Daylight Saving Period` is Yes (the default) and the file gives one.
//!
//! - an nth weekday the month lacks in the run's year (a 5th Monday in a month with four), in a
//!   special day, a daylight saving date or the weather file's record: EnergyPlus stops with a
//!   fatal error ("Nth Day of Month, not enough Nths", `SetSpecialDayDates`/`SetDSTDateRanges`),
//!   and sunlit refuses it naming the object (or weather file) and field.
//!
//! Only the first RunPeriod is read: sunlit's year is one run period's.

use super::idf::IdfObject;
use crate::error::{Error, Result};

/// Day types in EnergyPlus's order: Sunday … Saturday, Holiday, SummerDesignDay,
/// WinterDesignDay, CustomDay1, CustomDay2.
pub const DAY_TYPES: usize = 12;
/// The day types' names, in [`DAY_TYPES`] order.
pub const DAY_TYPE_NAMES: [&str; DAY_TYPES] = [
    "Sunday",
    "Monday",
    "Tuesday",
    "Wednesday",
    "Thursday",
    "Friday",
    "Saturday",
    "Holiday",
    "SummerDesignDay",
    "WinterDesignDay",
    "CustomDay1",
    "CustomDay2",
];
/// Days per month, February with its 29th.
pub const MONTH_DAYS: [u32; 12] = [31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
const MONTH_NAMES: [&str; 12] =
    ["january", "february", "march", "april", "may", "june", "july", "august", "september", "october", "november", "december"];
/// The day type EnergyPlus 25.2 gives a weather file's holidays (Sunday; see the module doc).
const WEATHER_HOLIDAY: usize = 0;
const SPECIAL_DAYS: &str = "RunPeriodControl:SpecialDays";
const DAYLIGHT_SAVING: &str = "RunPeriodControl:DaylightSavingTime";
/// The EPW header record that holds the file's holidays and daylight saving period.
const EPW_RECORD: &str = "HOLIDAYS/DAYLIGHT SAVINGS";

/// A date as EnergyPlus's special days and daylight saving give it: a month and day, or the nth
/// (1–5, or last) weekday of a month.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DateRule {
    /// Month (1–12) and day.
    Fixed(usize, u32),
    /// Which (1–5; 0 for the last), weekday (0 = Sunday), month (1–12).
    Nth(u32, usize, usize),
}

impl DateRule {
    /// `4/1`, `April 1`, `1 April`, `2nd Sunday in March`, `Last Sunday in October` (EnergyPlus's
    /// date forms; month names may be cut to three letters).
    pub fn parse(text: &str) -> Option<Self> {
        let text = text.trim().to_ascii_lowercase();
        let month = |w: &str| MONTH_NAMES.iter().position(|m| w.len() >= 3 && m.starts_with(w)).map(|m| m + 1);
        let words: Vec<&str> = text.split_whitespace().collect();
        let fixed = |m: usize, d: &str| {
            let d: u32 = d.parse().ok()?;
            (d >= 1 && d <= MONTH_DAYS[m - 1]).then_some(DateRule::Fixed(m, d))
        };
        match words.as_slice() {
            [one] => {
                let (m, d) = one.split_once('/')?;
                let m: usize = m.parse().ok().filter(|m| (1..=12).contains(m))?;
                fixed(m, d)
            }
            [a, b] => match (month(a), month(b)) {
                (Some(m), None) => fixed(m, b),
                (None, Some(m)) => fixed(m, a),
                _ => None,
            },
            [which, weekday, "in" | "of", m] => {
                let which = match *which {
                    "last" => 0,
                    w => w.trim_end_matches(|c: char| c.is_ascii_alphabetic()).parse().ok().filter(|n| (1..=5).contains(n))?,
                };
                let weekday = DAY_TYPE_NAMES[..7].iter().position(|n| n.eq_ignore_ascii_case(weekday))?;
                Some(DateRule::Nth(which, weekday, month(m)?))
            }
            _ => None,
        }
    }

    /// The day of the run's year (1-based; Feb 29 counted only in a leap run) given the weekday
    /// of 1 January; None for an nth weekday the month does not have that year (a 5th Monday
    /// in a month with four), on which EnergyPlus stops ("not enough Nths" in WeatherManager's
    /// `SetSpecialDayDates` and `SetDSTDateRanges`, a fatal error).
    ///
    /// In a leap year EnergyPlus 25.2 places an nth (or last) weekday of a month after February
    /// as if the year had no Feb 29, one day after the weekday itself: "2nd Sunday in March" is
    /// 9 March 2020 (a Monday), "Last Sunday in October" 26 October 2020, while February's own
    /// are right ("5th Saturday in February" 29 February 2020): its eio's `Environment:Daylight
    /// Saving` and `Environment:Special Days` dates, and the schedule values of
    /// tests/energyplus_schedules.rs. sunlit places them where EnergyPlus does.
    pub fn day(self, leap: bool, first_weekday: usize) -> Option<u32> {
        if let (DateRule::Nth(_, _, month), true) = (self, leap)
            && month > 2
        {
            return Some(self.day(false, first_weekday)? + 1);
        }
        let lengths = |m: usize| if m == 2 && !leap { 28 } else { MONTH_DAYS[m - 1] };
        let before = |m: usize| (1..m).map(lengths).sum::<u32>();
        match self {
            DateRule::Fixed(m, d) => Some(before(m) + d.min(lengths(m))),
            DateRule::Nth(which, weekday, m) => {
                let weekday_of = |day: u32| (first_weekday + day as usize - 1) % 7;
                if which == 0 {
                    let last = before(m) + lengths(m);
                    Some(last - ((weekday_of(last) + 7 - weekday) % 7) as u32)
                } else {
                    let first = before(m) + 1;
                    let day = first + ((weekday + 7 - weekday_of(first)) % 7) as u32 + 7 * (which - 1);
                    (day <= before(m) + lengths(m)).then_some(day)
                }
            }
        }
    }

    /// `5th Monday of December`, for messages (a fixed date as month/day).
    fn describe(self) -> String {
        match self {
            DateRule::Fixed(m, d) => format!("{m}/{d}"),
            DateRule::Nth(which, weekday, m) => {
                let ordinal = match which {
                    0 => "last".to_string(),
                    1 => "1st".to_string(),
                    2 => "2nd".to_string(),
                    3 => "3rd".to_string(),
                    n => format!("{n}th"),
                };
                let month = MONTH_NAMES[m - 1];
                let month = format!("{}{}", month[..1].to_ascii_uppercase(), &month[1..]);
                format!("{ordinal} {} of {month}", DAY_TYPE_NAMES[weekday])
            }
        }
    }
}

/// A date and where it was given (file, object, field), so that one EnergyPlus cannot place in
/// the run's year is refused naming them.
#[derive(Debug, Clone, PartialEq)]
struct Dated {
    rule: DateRule,
    file: String,
    object: String,
    field: String,
}

impl Dated {
    /// [`DateRule::day`], or the refusal EnergyPlus's fatal error stands for.
    fn day(&self, leap: bool, first_weekday: usize) -> Result<u32> {
        self.rule.day(leap, first_weekday).ok_or_else(|| {
            Error::object(
                &self.file,
                &self.object,
                format!(
                    "field '{}': there is no {} in the run's year (EnergyPlus stops on such a date: \"Nth Day of Month, not enough Nths\"); use 'Last' or a date",
                    self.field,
                    self.rule.describe()
                ),
            )
        })
    }
}

/// One special day period: its first date, its length in days and its day type.
#[derive(Debug, Clone, PartialEq)]
struct SpecialDay {
    start: Dated,
    duration: u32,
    day_type: usize,
}

/// What the weather file says of its calendar: its holidays and daylight saving period.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WeatherDays {
    holidays: Vec<Dated>,
    saving: Option<(Dated, Dated)>,
}

impl WeatherDays {
    /// The EPW's `HOLIDAYS/DAYLIGHT SAVINGS` record (its fifth line): `LeapYear, DST start, DST
    /// end, count, (name, date) × count`; a DST date of 0 or blank means none. A file without the
    /// record has neither. `file` names the file in errors.
    pub fn from_epw_text(file: &str, text: &str) -> Result<Self> {
        let Some(line) = text.lines().take(8).find(|l| l.trim_start().to_ascii_uppercase().starts_with(EPW_RECORD)) else {
            return Ok(Self::default());
        };
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let at = |i: usize| fields.get(i).copied().unwrap_or("");
        let bad = |what: String| Error::object(file, EPW_RECORD, what);
        let date = |i: usize, what: &str| match at(i) {
            "" | "0" => Ok(None),
            text => DateRule::parse(text)
                .map(|rule| Some(Dated { rule, file: file.to_string(), object: EPW_RECORD.to_string(), field: what.to_string() }))
                .ok_or_else(|| bad(format!("{what} '{text}' is not a date (M/D, Month D, or Nth Weekday in Month)"))),
        };
        let saving = match (date(2, "the daylight saving start")?, date(3, "the daylight saving end")?) {
            (Some(a), Some(b)) => Some((a, b)),
            _ => None,
        };
        let count = match at(4) {
            "" => 0,
            text => text.parse::<usize>().map_err(|_| bad(format!("the holiday count '{text}' is not a whole number")))?,
        };
        let holidays = (0..count)
            .map(|k| {
                date(6 + 2 * k, &format!("holiday {} ('{}'): its date", k + 1, at(5 + 2 * k)))?
                    .ok_or_else(|| bad(format!("holiday {} has no date", k + 1)))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self { holidays, saving })
    }
}

/// The model's side of the run's calendar (see the module doc); the weather file's side is
/// [`WeatherDays`], given when the values are asked for.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ModelCalendar {
    /// Weekday of 1 January (0 = Sunday).
    first_weekday: usize,
    special: Vec<SpecialDay>,
    /// `RunPeriodControl:DaylightSavingTime`'s start and end.
    saving: Option<(Dated, Dated)>,
    use_weather_holidays: bool,
    use_weather_saving: bool,
    weekend_rule: bool,
}

impl ModelCalendar {
    /// The calendar of `objects` (from `file`); refused, naming the object and field, for a
    /// special day or daylight saving date that cannot be read, a duration outside 1..366 or an
    /// unknown special day type.
    pub fn read(file: &str, objects: &[IdfObject]) -> Result<Self> {
        let bad = |o: &IdfObject, why: String| Error::object(file, o.label(), why);
        let dated = |o: &IdfObject, i: usize, field: &str| {
            let rule = date(o, i, field).map_err(|why| bad(o, why))?;
            Ok::<_, Error>(Dated { rule, file: file.to_string(), object: o.label(), field: field.to_string() })
        };
        let mut special = Vec::new();
        for o in objects.iter().filter(|o| o.is(SPECIAL_DAYS)) {
            let start = dated(o, 1, "Start Date")?;
            let duration = match o.field(2).trim() {
                "" => 1,
                text => text
                    .parse::<f64>()
                    .ok()
                    .filter(|d| d.fract() == 0.0 && (1.0..=366.0).contains(d))
                    .ok_or_else(|| bad(o, format!("field 'Duration': '{text}' is not a whole number of days from 1 to 366")))?
                    as u32,
            };
            let kind = o.field(3).trim();
            let day_type = match kind {
                "" => 7,
                _ => DAY_TYPE_NAMES[7..].iter().position(|n| n.eq_ignore_ascii_case(kind)).map(|t| t + 7).ok_or_else(|| {
                    bad(
                        o,
                        format!(
                            "field 'Special Day Type': '{kind}' is not Holiday, SummerDesignDay, WinterDesignDay, CustomDay1 or CustomDay2"
                        ),
                    )
                })?,
            };
            special.push(SpecialDay { start, duration, day_type });
        }
        let saving = match objects.iter().find(|o| o.is(DAYLIGHT_SAVING)) {
            Some(o) => Some((dated(o, 0, "Start Date")?, dated(o, 1, "End Date")?)),
            None => None,
        };
        let run = RunPeriodFields::first(objects);
        Ok(Self {
            first_weekday: run.as_ref().map_or(0, RunPeriodFields::first_weekday),
            special,
            saving,
            use_weather_holidays: run.as_ref().is_none_or(|r| r.yes(r.holidays, true)),
            use_weather_saving: run.as_ref().is_none_or(|r| r.yes(r.holidays + 1, true)),
            weekend_rule: run.as_ref().is_some_and(|r| r.yes(r.holidays + 2, false)),
        })
    }

    /// Weekday (0 = Sunday) of day `day` (1-based) of the run's year.
    fn weekday(&self, day: u32) -> usize {
        (self.first_weekday + day as usize - 1) % 7
    }

    /// The day type ([`DAY_TYPE_NAMES`] index) of every day of the run's year, in order; refused,
    /// naming the object (or weather file) and field, for an nth weekday the run's year does not
    /// have, on which EnergyPlus stops.
    pub fn day_types(&self, leap: bool, weather: Option<&WeatherDays>) -> Result<Vec<usize>> {
        let days = 365 + u32::from(leap);
        let mut types: Vec<usize> = (1..=days).map(|d| self.weekday(d)).collect();
        let from_weather = weather.filter(|_| self.use_weather_holidays).map_or(&[][..], |w| &w.holidays[..]);
        let periods = from_weather
            .iter()
            .map(|start| SpecialDay { start: start.clone(), duration: 1, day_type: WEATHER_HOLIDAY })
            .chain(self.special.iter().cloned());
        for special in periods {
            let mut day = special.start.day(leap, self.first_weekday)?;
            if self.weekend_rule && special.duration == 1 && matches!(special.start.rule, DateRule::Fixed(..)) {
                day += match self.weekday(day) {
                    0 => 1,
                    6 => 2,
                    _ => 0,
                };
            }
            for k in 0..special.duration {
                // Past 31 December the period goes on from 1 January.
                let d = (day - 1 + k) % days;
                types[d as usize] = special.day_type;
            }
        }
        Ok(types)
    }

    /// Whether each day of the run's year is in daylight saving, in order; refused as
    /// [`Self::day_types`] for a date the run's year does not have.
    pub fn saving_days(&self, leap: bool, weather: Option<&WeatherDays>) -> Result<Vec<bool>> {
        let days = 365 + u32::from(leap);
        let from_weather = weather.filter(|_| self.use_weather_saving).and_then(|w| w.saving.as_ref());
        let Some((start, end)) = self.saving.as_ref().or(from_weather) else { return Ok(vec![false; days as usize]) };
        let (start, end) = (start.day(leap, self.first_weekday)?, end.day(leap, self.first_weekday)?);
        Ok((1..=days).map(|d| if start <= end { (start..=end).contains(&d) } else { d >= start || d <= end }).collect())
    }

    /// Every date of the run's calendar placed in the run's year (the special days, the weather
    /// file's holidays when used, the daylight saving period in use), as EnergyPlus places them at
    /// the start of a run whether or not a schedule reads them: refused as [`Self::day_types`].
    pub fn check(&self, leap: bool, weather: Option<&WeatherDays>) -> Result<()> {
        self.day_types(leap, weather)?;
        self.saving_days(leap, weather).map(|_| ())
    }
}

/// The run's calendar of the model `objects` (from `file`) checked for the run's year: every special
/// day and daylight saving date placed, as EnergyPlus does at the start of a weather-file run and
/// stops on one it cannot place ([`ModelCalendar::check`]).
pub fn check_model(file: &str, objects: &[IdfObject], leap: bool, weather: Option<&WeatherDays>) -> Result<()> {
    ModelCalendar::read(file, objects)?.check(leap, weather)
}

/// A date field of `object`, or why it cannot be read.
fn date(object: &IdfObject, i: usize, field: &str) -> std::result::Result<DateRule, String> {
    let text = object.field(i).trim();
    DateRule::parse(text).ok_or_else(|| format!("field '{field}': '{text}' is not a date (M/D, Month D, or Nth Weekday in Month)"))
}

/// The first RunPeriod's fields that set the calendar, wherever its version puts them.
struct RunPeriodFields<'a> {
    object: &'a IdfObject,
    /// Begin Year's field, if the version has one.
    year: Option<usize>,
    /// `Day of Week for Start Day`'s field.
    start_weekday: usize,
    /// `Use Weather File Holidays and Special Days`'s field; the daylight saving and weekend
    /// rule switches follow it.
    holidays: usize,
}

impl<'a> RunPeriodFields<'a> {
    fn first(objects: &'a [IdfObject]) -> Option<Self> {
        let object = objects.iter().find(|o| o.is("RunPeriod"))?;
        let version = super::idf::version(objects);
        // Before 9.0 the RunPeriod had no Begin and End Year.
        let old = super::building::IddLayout::from_version(version.as_deref()).shading_control;
        Some(if old {
            Self { object, year: None, start_weekday: 5, holidays: 6 }
        } else {
            Self { object, year: Some(3), start_weekday: 7, holidays: 8 }
        })
    }

    /// A Yes/No field; blank is `default`.
    fn yes(&self, i: usize, default: bool) -> bool {
        match self.object.field(i).trim() {
            "" => default,
            text => text.eq_ignore_ascii_case("yes"),
        }
    }

    /// The weekday (0 = Sunday) of 1 January: from the Begin Year (what weekday 1 January of
    /// that year is), else the `Day of Week for Start Day` counted back to 1 January from the
    /// begin date, else Sunday.
    fn first_weekday(&self) -> usize {
        let o = self.object;
        let begin = month_day(&format!("{}/{}", o.field(1), o.field(2))).unwrap_or(1);
        if let Some(year) = self.year.and_then(|i| o.field(i).trim().parse::<i64>().ok()) {
            // Days from a known Sunday (1 January 2017) to 1 January of `year`.
            let days_before = |y: i64| 365 * y + y.div_euclid(4) - y.div_euclid(100) + y.div_euclid(400);
            return (days_before(year - 1) - days_before(2016)).rem_euclid(7) as usize;
        }
        match DAY_TYPE_NAMES[..7].iter().position(|n| n.eq_ignore_ascii_case(o.field(self.start_weekday).trim())) {
            // Non-leap numbering of the begin day; 1 January is that many days earlier.
            Some(start) => (start as i64 - (begin as i64 - 1 - i64::from(begin > 60))).rem_euclid(7) as usize,
            None => 0,
        }
    }
}

/// `MM/DD` (or `M/D`) as a day of a leap year (1–366: schedules number Feb 29 as day 60).
pub fn month_day(text: &str) -> Option<u32> {
    let (m, d) = text.trim().split_once('/')?;
    let (m, d): (usize, u32) = (m.trim().parse().ok()?, d.trim().parse().ok()?);
    let length = *MONTH_DAYS.get(m.checked_sub(1)?)?;
    (d >= 1 && d <= length).then(|| MONTH_DAYS[..m - 1].iter().sum::<u32>() + d)
}

#[cfg(test)]
#[path = "calendar_tests.rs"]
mod tests;
