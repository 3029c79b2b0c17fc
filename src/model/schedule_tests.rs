#![allow(clippy::unwrap_used)]
use super::*;
use crate::model::calendar::DateRule;
use crate::model::idf::parse_idf;

const N4: RunCalendar = RunCalendar { per_hour: 4, leap: false, weather: None };

fn schedule(text: &str, name: &str) -> Result<Schedule> {
    let objects = parse_idf("m.idf", text)?;
    let schedules = Schedules::new("m.idf", &objects, None);
    schedules.resolve(name, "Shading:Site:Detailed 'Tree' (line 1)", "Transmittance Schedule Name")
}

/// Row of (1-based day, timestep ending at `hh:mm`) with 4 timesteps an hour.
fn row(day: usize, hh: usize, mm: usize) -> usize {
    (day - 1) * 96 + (hh * 60 + mm) / 15 - 1
}

#[test]
fn constant_and_compact_until_values_hold_up_to_their_time() {
    let c = schedule("Schedule:Constant, C, , 0.2;", "c").unwrap();
    assert_eq!(c.constant(), Some(0.2));
    assert_eq!(c.values(N4).unwrap().len(), 365 * 96);
    let text = "Schedule:Compact, S, ,\n Through: 3/31, For: AllDays, Until: 12:00, 0.1, Until: 24:00, 0.3,\n Through: 12/31, For: Weekdays, Until: 24:00, 0.5, For: AllOtherDays, Until: 24:00, 0.7;\n RunPeriod, R, 1, 1, 2017, 12, 31, 2017;";
    let s = schedule(text, "S").unwrap();
    let v = s.values(N4).unwrap();
    assert_eq!(v[row(1, 12, 0)], 0.1, "the step ending at 12:00 is before the Until");
    assert_eq!(v[row(1, 12, 15)], 0.3);
    assert_eq!(v[row(90, 24, 0)], 0.3, "31 March");
    // 2017 starts on a Sunday: 2 April is a Sunday, 3 April a Monday.
    assert_eq!(v[row(92, 10, 0)], 0.7);
    assert_eq!(v[row(93, 10, 0)], 0.5);
}

#[test]
fn interpolation_averages_or_ramps_within_a_timestep() {
    let text = "Schedule:Compact, S, , Through: 12/31, For: AllDays, Interpolate: Average, Until: 10:10, 0, Until: 24:00, 1;";
    let v = schedule(text, "S").unwrap().values(N4).unwrap();
    assert_eq!(v[row(1, 10, 15)], 1.0 / 3.0);
    let text = "Schedule:Compact, S, , Through: 12/31, For: AllDays, Interpolate: No, Until: 10:10, 0, Until: 24:00, 1;";
    let v = schedule(text, "S").unwrap().values(N4).unwrap();
    assert_eq!(v[row(1, 10, 15)], 1.0, "No: the value holding at the step's end");
    let text = "Schedule:Compact, S, , Through: 12/31, For: AllDays, Interpolate: Linear, Until: 12:00, 0, Until: 24:00, 1;";
    let v = schedule(text, "S").unwrap().values(N4).unwrap();
    assert!(v[row(1, 12, 15)] > 0.0 && v[row(1, 12, 15)] < 0.03, "{}", v[row(1, 12, 15)]);
    assert!((v[row(1, 18, 0)] - 0.5).abs() < 0.02, "{}", v[row(1, 18, 0)]);
}

#[test]
fn year_week_and_day_schedules() {
    let text = "Schedule:Year, Y, , W1, 1, 1, 6, 30, W2, 7, 1, 12, 31;\n\
        Schedule:Week:Daily, W1, D1, D1, D1, D1, D1, D1, D1, D1, D1, D1, D1, D1;\n\
        Schedule:Week:Daily, W2, D2, D2, D2, D2, D2, D2, D2, D2, D2, D2, D2, D2;\n\
        Schedule:Day:Hourly, D1, , 0,0,0,0,0,0,0,0,0,0,0,0.5,0,0,0,0,0,0,0,0,0,0,0,0;\n\
        Schedule:Day:Interval, D2, , No, 06:00, 1, 24:00, 0.25;";
    let s = schedule(text, "y").unwrap();
    let v = s.values(N4).unwrap();
    assert_eq!((v[row(1, 11, 45)], v[row(1, 12, 0)], v[row(1, 11, 0)]), (0.5, 0.5, 0.0), "hour 12 is 11:00–12:00");
    assert_eq!((v[row(182, 6, 0)], v[row(182, 6, 15)]), (1.0, 0.25), "1 July");
    let leap = s.values(RunCalendar { per_hour: 1, leap: true, weather: None }).unwrap();
    assert_eq!(leap.len(), 366 * 24);
    let hours = vec!["0"; 24].join(",");
    let half = format!(
        "Schedule:Year, Y, , W1, 1, 1, 6, 30;\nSchedule:Week:Daily, W1, D,D,D,D,D,D,D,D,D,D,D,D;\nSchedule:Day:Hourly, D, , {hours};"
    );
    let e = schedule(&half, "Y").unwrap_err().to_string();
    assert!(e.contains("Schedule:Year 'Y'") && e.contains("its weeks leave 07/01 without a week schedule"), "{e}");
    let e = schedule(&half.replace(&hours, "0"), "Y").unwrap_err().to_string();
    assert!(e.contains("Schedule:Day:Hourly 'D'") && e.contains("field 'Hour 2': '' is not a number"), "{e}");
}

#[test]
fn refusals_name_object_field_and_reason() {
    let e = schedule("Schedule:Constant, C, , 0.2;", "nope").unwrap_err().to_string();
    assert!(e.contains("Tree") && e.contains("Transmittance Schedule Name") && e.contains("'nope' names no schedule"), "{e}");
    let e = schedule("Schedule:Compact, S, , Through: 6/30, For: AllDays, Until: 24:00, 1;", "S").unwrap_err().to_string();
    assert!(e.contains("Schedule:Compact 'S'") && e.contains("end on 06/30, not on 12/31"), "{e}");
    let e = schedule("Schedule:Constant, C, Frac, 1.5;\nScheduleTypeLimits, Frac, 0, 1, Continuous;", "C").unwrap_err().to_string();
    assert!(e.contains("value 1.5 is outside its ScheduleTypeLimits 'Frac' (0..1)"), "{e}");
    let e = schedule("Schedule:Constant, C, Missing, 0.5;", "C").unwrap_err().to_string();
    assert!(e.contains("'Missing' names no ScheduleTypeLimits"), "{e}");
    let e = schedule("Schedule:Constant, C, On, 0.5;\nScheduleTypeLimits, On, 0, 1, Discrete;", "C").unwrap_err().to_string();
    assert!(e.contains("discrete"), "{e}");
    let e = schedule("Schedule:Compact, S, , Through: 12/31, For: AllDays, Until: 12:00, 1;", "S").unwrap_err().to_string();
    assert!(e.contains("not 24:00"), "{e}");
    let e = schedule("Schedule:File, F, , /nonexistent/t.csv, 1, 0;", "F").unwrap_err().to_string();
    assert!(e.contains("Schedule:File 'F'") && e.contains("cannot be read"), "{e}");
}

#[test]
fn schedule_file_reads_its_column_and_refuses_a_short_file() {
    let dir = std::env::temp_dir().join(format!("sunlit-schedule-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rows: Vec<String> = (0..8760 * 4).map(|i| format!("x,{}", if i % 96 < 48 { 0.25 } else { 0.75 })).collect();
    std::fs::write(dir.join("t.csv"), format!("head\n{}\n", rows.join("\n"))).unwrap();
    std::fs::write(dir.join("short.csv"), "0.5\n0.5\n").unwrap();
    let text = "Schedule:File, F, , t.csv, 2, 1, 8760, Comma, No, 15;\nSchedule:File, G, , short.csv, 1, 0;";
    let objects = parse_idf("m.idf", text).unwrap();
    let schedules = Schedules::new("m.idf", &objects, Some(&dir));
    let v = schedules.resolve("F", "x", "y").unwrap().values(N4).unwrap();
    assert_eq!((v[row(2, 12, 0)], v[row(2, 12, 15)]), (0.25, 0.75));
    let hourly = schedules.resolve("F", "x", "y").unwrap().values(RunCalendar { per_hour: 1, leap: false, weather: None }).unwrap();
    assert_eq!(hourly[12], 0.75, "one timestep an hour: the value at the hour's end");
    let e = schedules.resolve("G", "x", "y").unwrap_err().to_string();
    assert!(e.contains("too short: 2 values") && e.contains("8760 needed"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `RunPeriodControl:DaylightSavingTime`'s date forms, on 2017 (1 January a Sunday).
#[test]
fn daylight_saving_dates_in_every_form() {
    let day = |text: &str| DateRule::parse(text).unwrap().day(false, 0).unwrap();
    assert_eq!(day("2nd Sunday in March"), 71, "12 March 2017");
    assert_eq!(day("1st Sunday in November"), 309, "5 November 2017");
    assert_eq!(day("Last Sunday in October"), 302, "29 October 2017");
    assert_eq!(day("4/1"), 91);
    assert_eq!(day("April 1"), 91);
    assert_eq!(day("1 Apr"), 91);
    assert_eq!(DateRule::parse("3/1").unwrap().day(true, 0), Some(61), "a leap run counts Feb 29");
    // 2020 (1 January a Wednesday): EnergyPlus 25.2 puts an nth weekday after February a day late.
    let leap_day = |text: &str| DateRule::parse(text).unwrap().day(true, 3).unwrap();
    assert_eq!(leap_day("1st Tuesday in February"), 35, "4 February 2020, before Feb 29: as it is");
    assert_eq!(leap_day("5th Saturday in February"), 60, "29 February 2020: February's own are right");
    assert_eq!(leap_day("2nd Sunday in March"), 69, "9 March 2020, EnergyPlus's date, not 8 March");
    assert_eq!(leap_day("Last Sunday in October"), 300, "26 October 2020, not 25 October");
    for bad in ["", "13/1", "2/30", "6th Sunday in March", "Sunday in March", "Funday 1"] {
        assert_eq!(DateRule::parse(bad), None, "{bad}");
    }
}

/// On daylight-saving days every timestep takes the value one hour later, as EnergyPlus looks
/// schedules up at the hour plus its DST indicator; a date it cannot read is refused by field.
#[test]
fn daylight_saving_shifts_values_by_an_hour() {
    let text = "Schedule:Compact, S, , Through: 12/31, For: AllDays, Until: 12:00, 0.1, Until: 24:00, 0.3;\n\
                RunPeriod, R, 1, 1, 2017, 12, 31, 2017;\nRunPeriodControl:DaylightSavingTime, 4/1, Last Sunday in October;";
    let v = schedule(text, "S").unwrap().values(N4).unwrap();
    assert_eq!(v[row(90, 11, 15)], 0.1, "31 March: standard time");
    assert_eq!(v[row(91, 11, 0)], 0.1, "1 April, 11:00 is noon's step in daylight time");
    assert_eq!(v[row(91, 11, 15)], 0.3);
    assert_eq!(v[row(302, 11, 15)], 0.3, "29 October, the last day");
    assert_eq!(v[row(303, 11, 15)], 0.1);
    let bad = text.replace("4/1", "Easter");
    let err = schedule(&bad, "S").unwrap_err().to_string();
    assert!(err.contains("RunPeriodControl:DaylightSavingTime") && err.contains("field 'Start Date': 'Easter' is not a date"), "{err}");
}

/// `Schedule:Compact` as EnergyPlus reads it: `Through:` dates with month names, keywords
/// without their colon, day types found by the words a `For:` contains; a day type given twice
/// in one period, and an nth weekday as a `Through:` date, refused as EnergyPlus refuses them.
#[test]
fn compact_reads_every_through_for_and_until_form() {
    let text = "Schedule:Compact, S, , Through: Mar 31, For: AllDays, Until: 24:00, 0.1,\n\
                Through 15 July, For Weekday, Until 12:00, 0.3, Until 24:00, 0.6, For AllOtherDay, Until 24:00, 0.5,\n\
                Through: December 31, For: Weekends Holidays, Until: 24:00, 0.9, For: AllOtherDays, Until: 24:00, 0.7;\n\
                RunPeriod, R, 1, 1, 2017, 12, 31, 2017;";
    let v = schedule(text, "S").unwrap().values(N4).unwrap();
    assert_eq!((v[row(90, 12, 0)], v[row(91, 12, 0)]), (0.1, 0.5), "31 March, then Saturday 1 April 2017");
    assert_eq!((v[row(93, 12, 0)], v[row(93, 12, 15)]), (0.3, 0.6), "Monday 3 April: Weekday");
    assert_eq!((v[row(196, 12, 0)], v[row(197, 12, 0)]), (0.5, 0.9), "Saturday 15 July, then Sunday 16 July in the third period");
    let twice = "Schedule:Compact, S, , Through: 12/31, For: Weekdays, Until: 24:00, 0.1, For: Monday, Until: 24:00, 0.2;";
    let e = schedule(twice, "S").unwrap_err().to_string();
    assert!(e.contains("field 7 'For: Monday' gives Monday a second time"), "{e}");
    let nth = "Schedule:Compact, S, , Through: Last Sunday in December, For: AllDays, Until: 24:00, 0.1;";
    let e = schedule(nth, "S").unwrap_err().to_string();
    assert!(e.contains("field 3 'Through: Last Sunday in December' is not Through: a date"), "{e}");
    let none = "Schedule:Compact, S, , Through: 12/31, For: Someday, Until: 24:00, 0.1;";
    assert!(schedule(none, "S").unwrap_err().to_string().contains("'Someday' names no day type"));
}

/// `Interpolate: Linear` ramps from one `Until` value to the next and takes the value at each
/// timestep's end (EnergyPlus 25.2's reported values); the first period is flat.
#[test]
fn linear_takes_the_ramp_at_the_steps_end_and_starts_flat() {
    let text = "Schedule:Compact, S, , Through: 12/31, For: AllDays, Interpolate: Linear, Until: 06:00, 0.2, Until: 12:00, 0.8, Until: 24:00, 0.4;";
    let v = schedule(text, "S").unwrap().values(N4).unwrap();
    assert_eq!(v[row(1, 0, 15)], 0.2, "the first period does not ramp from the day's last value");
    assert!((v[row(1, 6, 15)] - 0.225).abs() < 1e-12, "{}", v[row(1, 6, 15)]);
    let text = "Schedule:Year, Y, , W, 1, 1, 12, 31;\nSchedule:Week:Daily, W, D,D,D,D,D,D,D,D,D,D,D,D;\n\
                Schedule:Day:Interval, D, , Linear, 06:00, 0.2, 12:00, 0.8, 24:00, 0.4;";
    let v = schedule(text, "Y").unwrap().values(N4).unwrap();
    assert!((v[row(1, 6, 15)] - 0.225).abs() < 1e-12, "{}", v[row(1, 6, 15)]);
}

/// `Schedule:Year`'s weeks in any order, one running over New Year, Feb 29 taking Feb 28's week;
/// a day covered twice or not at all refused naming the date.
#[test]
fn year_weeks_in_any_order_and_feb_29() {
    let days = "Schedule:Week:Daily, A, DA,DA,DA,DA,DA,DA,DA,DA,DA,DA,DA,DA;\nSchedule:Week:Daily, B, DB,DB,DB,DB,DB,DB,DB,DB,DB,DB,DB,DB;\n\
                Schedule:Day:Interval, DA, , No, 24:00, 0.25;\nSchedule:Day:Interval, DB, , No, 24:00, 0.75;\n";
    let year = |weeks: &str| schedule(&format!("Schedule:Year, Y, , {weeks};\n{days}"), "Y");
    let leap = RunCalendar { per_hour: 4, leap: true, weather: None };
    let v = year("B, 11, 1, 2, 28, A, 3, 1, 10, 31").unwrap().values(leap).unwrap();
    assert_eq!((v[row(59, 12, 0)], v[row(60, 12, 0)], v[row(61, 12, 0)]), (0.75, 0.75, 0.25), "Feb 28, 29 and Mar 1");
    assert_eq!((v[row(305, 12, 0)], v[row(306, 12, 0)]), (0.25, 0.75), "31 October, 1 November (leap)");
    let e = year("A, 1, 1, 6, 30, B, 6, 30, 12, 31").unwrap_err().to_string();
    assert!(e.contains("week 2 ('B') covers 06/30 again"), "{e}");
    let e = year("A, 1, 1, 6, 29, B, 7, 1, 12, 31").unwrap_err().to_string();
    assert!(e.contains("its weeks leave 06/30 without a week schedule"), "{e}");
}

/// A leap (8,784-hour) `Schedule:File` skips its Feb 29 in a plain year; a plain file gives a
/// leap year's Feb 29 its Feb 28; `Adjust Schedule for Daylight Savings` No keeps standard time.
#[test]
fn schedule_file_days_in_plain_and_leap_years_and_daylight_saving() {
    let dir = std::env::temp_dir().join(format!("sunlit-schedule-leap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let day_numbers = |hours: usize| (0..hours).map(|h| format!("{}", (h / 24 + 1) as f64 / 1000.0)).collect::<Vec<_>>().join("\n");
    std::fs::write(dir.join("leap.csv"), day_numbers(8784)).unwrap();
    std::fs::write(dir.join("plain.csv"), day_numbers(8760)).unwrap();
    let text = "Schedule:File, L, , leap.csv, 1, 0, 8784;\nSchedule:File, P, , plain.csv, 1, 0;\n\
                Schedule:File, S, , plain.csv, 1, 0, 8760, Comma, No, 60, No;\nSchedule:File, H, , plain.csv, 1, 0, 9000;\n\
                RunPeriodControl:DaylightSavingTime, 4/1, 10/31;";
    let objects = parse_idf("m.idf", text).unwrap();
    let schedules = Schedules::new("m.idf", &objects, Some(&dir));
    let at = |name: &str, leap: bool, day: usize| {
        let v = schedules.resolve(name, "x", "y").unwrap().values(RunCalendar { per_hour: 4, leap, weather: None }).unwrap();
        v[row(day, 12, 0)]
    };
    assert_eq!((at("L", false, 59), at("L", false, 60)), (0.059, 0.061), "a plain year skips the file's Feb 29");
    assert_eq!((at("L", true, 60), at("L", true, 366)), (0.060, 0.366));
    assert_eq!((at("P", true, 59), at("P", true, 60), at("P", true, 61)), (0.059, 0.059, 0.060), "Feb 29 is Feb 28 again");
    assert_eq!(at("P", false, 365), 0.365);
    let hours =
        |name: &str| schedules.resolve(name, "x", "y").unwrap().values(RunCalendar { per_hour: 1, leap: false, weather: None }).unwrap();
    assert_eq!(
        (hours("P")[100 * 24 + 23], hours("S")[100 * 24 + 23]),
        (0.102, 0.101),
        "11 April, the last hour: a day later in daylight time"
    );
    let e = schedules.resolve("H", "x", "y").unwrap_err().to_string();
    assert!(e.contains("Schedule:File 'H'") && e.contains("field 'Number of Hours of Data': 9000 is neither 8760 nor 8784"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `Schedule:Week:Compact` gives day schedules by `For:` words (the prefix optional,
/// `AllOtherDays` for the rest); `Schedule:Day:List` holds a value per `Minutes per Item`, read at
/// each timestep's end (No, and Linear as EnergyPlus 25.2 reads it) or averaged over it.
#[test]
fn week_compact_and_day_list_read_as_energyplus_does() {
    let hours: Vec<String> = (0..24).map(|h| format!("{}", h as f64 / 100.0)).collect();
    let tens: Vec<String> = (0..144).map(|k| format!("{}", (k % 3) as f64 / 2.0)).collect();
    let text = format!(
        "Schedule:Year, Y, , W, 1, 1, 12, 31;\n\
         Schedule:Week:Compact, W, For: Weekdays, HOURS, Weekends Holiday, TENS, For: AllOtherDays, LINEAR;\n\
         Schedule:Day:List, HOURS, , No, 60, {};\nSchedule:Day:List, TENS, , Average, 10, {};\n\
         Schedule:Day:List, LINEAR, , Linear, 10, {};\nRunPeriod, R, 1, 1, 2017, 12, 31, 2017;",
        hours.join(", "),
        tens.join(", "),
        tens.join(", ")
    );
    let v = schedule(&text, "Y").unwrap().values(N4).unwrap();
    // 2017 starts on a Sunday: 1 January takes TENS, 2 January (Monday) HOURS.
    assert_eq!((v[row(2, 12, 0)], v[row(2, 12, 15)]), (0.11, 0.12), "hour 12 is 11:00–12:00");
    // 10-minute items 0, 0.5, 1, 0, …: the step 00:00–00:15 averages 10 minutes of 0 and 5 of 0.5.
    assert!((v[row(1, 0, 15)] - 0.5 / 3.0).abs() < 1e-12, "{}", v[row(1, 0, 15)]);
    let list = schedule(&text.replace("For: Weekdays, HOURS, Weekends Holiday, TENS, For: AllOtherDays, LINEAR", "AllDays, LINEAR"), "Y");
    let v = list.unwrap().values(N4).unwrap();
    assert_eq!((v[row(1, 0, 15)], v[row(1, 0, 30)]), (0.5, 1.0), "Linear: the item holding at the step's end, not ramped");
}

/// A week that leaves a day type without a day schedule or gives one twice, a day type it cannot
/// read, a day schedule that does not exist, and a list of the wrong length, with items that do
/// not divide an hour or a value that is not a number: each refused naming object, field and reason.
#[test]
fn week_compact_and_day_list_refusals_name_object_field_and_reason() {
    let day = "Schedule:Day:List, D, , No, 60, 0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0.5;\n";
    let week = |pairs: &str| schedule(&format!("Schedule:Year, Y, , W, 1, 1, 12, 31;\nSchedule:Week:Compact, W, {pairs};\n{day}"), "Y");
    let e = week("For: Weekdays, D, For: Weekends, D").unwrap_err().to_string();
    assert!(e.contains("Schedule:Week:Compact 'W' (line 2): its DayType Lists give Holiday no day schedule"), "{e}");
    let e = week("For: Weekdays, D, For: Monday Holiday, D, AllOtherDays, D").unwrap_err().to_string();
    assert!(
        e.contains("Schedule:Week:Compact 'W'") && e.contains("field 4 'DayType List 2' gives Monday a second time in this week"),
        "{e}"
    );
    let e = week("For: Someday, D").unwrap_err().to_string();
    assert!(e.contains("field 2 'DayType List 1' 'For: Someday' names no day type"), "{e}");
    let e = week("AllDays, NOPE").unwrap_err().to_string();
    assert!(e.contains("field 3 'Schedule:Day Name 1': 'NOPE' names no Schedule:Day:Hourly, :Interval or :List"), "{e}");
    let list = |body: &str| schedule(&format!("Schedule:Year, Y, , W, 1, 1, 12, 31;\nSchedule:Week:Compact, W, AllDays, D;\n{body}"), "Y");
    let e = list("Schedule:Day:List, D, , No, 60, 0,0,0;").unwrap_err().to_string();
    assert!(e.contains("Schedule:Day:List 'D' (line 3): it has 3 values, and 60-minute items need 24 to fill the day"), "{e}");
    let e = list("Schedule:Day:List, D, , No, 7, 0;").unwrap_err().to_string();
    assert!(e.contains("Schedule:Day:List 'D'") && e.contains("field 'Minutes per Item': 7 does not divide an hour"), "{e}");
    let e = list(&day.replace("0.5;", "x;")).unwrap_err().to_string();
    assert!(e.contains("Schedule:Day:List 'D'") && e.contains("field 'Value 24': 'x' is not a number"), "{e}");
    let e = list(&day.replace("No, 60", "Sometimes, 60")).unwrap_err().to_string();
    assert!(e.contains("field 'Interpolate to Timestep' is not No, Average or Linear"), "{e}");
    let e = schedule("Schedule:Year, Y, , W, 1, 1, 12, 31;", "Y").unwrap_err().to_string();
    assert!(e.contains("'W' names no Schedule:Week:Daily or Schedule:Week:Compact"), "{e}");
}
