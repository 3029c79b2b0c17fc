#![allow(clippy::unwrap_used)]
use super::*;
use crate::model::idf::parse_idf;

fn calendar(text: &str) -> Result<ModelCalendar> {
    ModelCalendar::read("m.idf", &parse_idf("m.idf", text)?)
}

/// `DAY_TYPE_NAMES` index by name.
fn t(name: &str) -> usize {
    DAY_TYPE_NAMES.iter().position(|n| *n == name).unwrap()
}

/// Special days on 2017 (1 January a Sunday): each form of date, durations over New Year, the
/// later of two on a shared day, and the weekend rule moving one-day month/day holidays only.
#[test]
fn special_days_set_the_day_type() {
    let text = "RunPeriod, R, 1, 1, 2017, 12, 31, 2017, , Yes, Yes, No;\n\
                RunPeriodControl:SpecialDays, MLK, 3rd Monday in January, 1, Holiday;\n\
                RunPeriodControl:SpecialDays, C, 1/18, 2, CustomDay1;\n\
                RunPeriodControl:SpecialDays, S, 1/21, 1, SummerDesignDay;\n\
                RunPeriodControl:SpecialDays, NY, 12/31, 3, CustomDay2;\n\
                RunPeriodControl:SpecialDays, OVER, 1/19, 1, WinterDesignDay;\n\
                RunPeriodControl:SpecialDays, BLANK, Last Friday in March;";
    let types = calendar(text).unwrap().day_types(false, None).unwrap();
    assert_eq!(types.len(), 365);
    assert_eq!(types[0], t("CustomDay2"), "12/31 for 3 days goes on into January");
    assert_eq!(types[1], t("CustomDay2"));
    assert_eq!(types[2], t("Tuesday"));
    assert_eq!(types[15], t("Holiday"), "16 January 2017, the 3rd Monday");
    assert_eq!((types[17], types[18]), (t("CustomDay1"), t("WinterDesignDay")), "the later one wins on 19 January");
    assert_eq!(types[20], t("SummerDesignDay"), "21 January, a Saturday, stays without the weekend rule");
    assert_eq!(types[89], t("Holiday"), "31 March 2017, blank duration 1 and type Holiday");
    let rule = calendar(&text.replace("Yes, Yes, No;", "Yes, Yes, Yes;")).unwrap().day_types(false, None).unwrap();
    assert_eq!((rule[20], rule[22]), (t("Saturday"), t("SummerDesignDay")), "Saturday's moves to Monday 23 January");
    assert_eq!(rule[15], t("Holiday"), "an nth-weekday date does not move");
}

/// The weather file's holidays are Sunday-type days (EnergyPlus 25.2, measured) when the
/// RunPeriod uses them; its daylight saving period holds unless the model has its own.
#[test]
fn weather_file_holidays_and_daylight_saving() {
    let epw = "LOCATION,X\nA\nB\nC\nHOLIDAYS/DAYLIGHT SAVINGS,No,1/17,1/19,2,Weather Holiday,1/20,Other,4th Thursday in November\n";
    let weather = WeatherDays::from_epw_text("w.epw", epw).unwrap();
    let run = |switches: &str, extra: &str| calendar(&format!("RunPeriod, R, 1, 1, 2017, 12, 31, 2017, , {switches};\n{extra}")).unwrap();
    let uses = run("Yes, Yes, No", "");
    let types = uses.day_types(false, Some(&weather)).unwrap();
    assert_eq!((types[19], types[326]), (t("Sunday"), t("Sunday")), "20 January and 23 November 2017");
    let saving = uses.saving_days(false, Some(&weather)).unwrap();
    assert_eq!((saving[15], saving[16], saving[18], saving[19]), (false, true, true, false));
    let ignores = run("No, No, No", "");
    assert_eq!(ignores.day_types(false, Some(&weather)).unwrap()[19], t("Friday"));
    assert!(!ignores.saving_days(false, Some(&weather)).unwrap().contains(&true));
    // The model's own daylight saving holds whatever the RunPeriod says of the weather file's.
    let own = run("No, No, No", "RunPeriodControl:DaylightSavingTime, 1/22, 1/22;");
    let saving = own.saving_days(false, Some(&weather)).unwrap();
    assert_eq!((saving[16], saving[21]), (false, true));
    let both = run("Yes, Yes, No", "RunPeriodControl:DaylightSavingTime, 1/22, 1/22;").saving_days(false, Some(&weather)).unwrap();
    assert!(!both[16] && both[21], "the model's period replaces the weather file's");
    // Defaults: a RunPeriod that leaves the switches blank uses the weather file's days.
    assert_eq!(calendar("RunPeriod, R, 1, 1, 2017, 12, 31, 2017;").unwrap().day_types(false, Some(&weather)).unwrap()[19], t("Sunday"));
    assert_eq!(
        WeatherDays::from_epw_text("w.epw", "LOCATION,X\nA\nB\nC\nHOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\n").unwrap(),
        WeatherDays::default()
    );
}

/// Special days and weather records sunlit cannot read are refused, naming object and field.
#[test]
fn unreadable_special_days_are_refused() {
    for (object, says) in [
        ("RunPeriodControl:SpecialDays, X, Easter, 1, Holiday;", "field 'Start Date': 'Easter' is not a date"),
        ("RunPeriodControl:SpecialDays, X, 1/1, 0, Holiday;", "field 'Duration': '0' is not a whole number of days from 1 to 366"),
        ("RunPeriodControl:SpecialDays, X, 1/1, 367, Holiday;", "field 'Duration': '367'"),
        ("RunPeriodControl:SpecialDays, X, 1/1, 1.5, Holiday;", "field 'Duration': '1.5'"),
        ("RunPeriodControl:SpecialDays, X, 1/1, 1, Festival;", "field 'Special Day Type': 'Festival' is not Holiday"),
        ("RunPeriodControl:DaylightSavingTime, 4/31, 10/1;", "field 'Start Date': '4/31' is not a date"),
    ] {
        let e = calendar(object).unwrap_err().to_string();
        let class = object.split(',').next().unwrap();
        assert!(e.contains("m.idf") && e.contains(class) && e.contains(says), "{object}: {e}");
    }
    let e = WeatherDays::from_epw_text("w.epw", "L\nA\nB\nC\nHOLIDAYS/DAYLIGHT SAVINGS,No,0,0,1,Fest,Easter\n").unwrap_err().to_string();
    assert!(e.contains("w.epw") && e.contains("HOLIDAYS/DAYLIGHT SAVINGS") && e.contains("holiday 1 ('Fest')"), "{e}");
}

/// The same calendar from epJSON: special days and the RunPeriod's switches by their keys.
#[test]
fn special_days_from_epjson() {
    let text = r#"{"RunPeriod": {"R": {"begin_month": 1, "begin_day_of_month": 1, "begin_year": 2017, "end_month": 12,
        "end_day_of_month": 31, "end_year": 2017, "use_weather_file_holidays_and_special_days": "No",
        "use_weather_file_daylight_saving_period": "Yes", "apply_weekend_holiday_rule": "Yes"}},
        "RunPeriodControl:SpecialDays": {"S": {"start_date": "1/21", "duration": 1, "special_day_type": "SummerDesignDay"},
        "C": {"start_date": "3rd Wednesday in January", "duration": 2, "special_day_type": "CustomDay1"}}}"#;
    let objects = crate::model::epjson::parse_epjson("m.epJSON", text).unwrap();
    let calendar = ModelCalendar::read("m.epJSON", &objects).unwrap();
    let weather = WeatherDays::from_epw_text("w.epw", "L\nA\nB\nC\nHOLIDAYS/DAYLIGHT SAVINGS,No,1/17,1/19,1,H,1/20\n").unwrap();
    let types = calendar.day_types(false, Some(&weather)).unwrap();
    assert_eq!((types[17], types[18], types[19]), (t("CustomDay1"), t("CustomDay1"), t("Friday")), "no weather holidays");
    assert_eq!((types[20], types[22]), (t("Saturday"), t("SummerDesignDay")), "the weekend rule");
    assert!(calendar.saving_days(false, Some(&weather)).unwrap()[16], "the weather file's daylight saving");
}

/// An nth weekday the month lacks in the run's year is refused naming the object (or the weather
/// file's record) and field, as EnergyPlus stops on it (`SetSpecialDayDates` and
/// `SetDSTDateRanges`: "Nth Day of Month, not enough Nths", fatal); sunlit used to take the
/// month's last day instead. December 2017 has five Fridays and four Mondays; February 2020 has
/// a fifth Saturday only when the run has its Feb 29.
#[test]
fn a_weekday_the_month_lacks_is_refused() {
    let run = "RunPeriod, R, 1, 1, 2017, 12, 31, 2017, , Yes, Yes, No;\n";
    let fifth_friday = calendar(&format!("{run}RunPeriodControl:SpecialDays, F, 5th Friday in December, 1, Holiday;")).unwrap();
    assert_eq!(fifth_friday.day_types(false, None).unwrap()[362], t("Holiday"), "29 December 2017");
    let fifth_monday = calendar(&format!("{run}RunPeriodControl:SpecialDays, IMPOSSIBLE, 5th Monday in December, 1, Holiday;")).unwrap();
    let e = fifth_monday.day_types(false, None).unwrap_err().to_string();
    assert!(
        e.contains("RunPeriodControl:SpecialDays 'IMPOSSIBLE'") && e.contains("'Start Date'") && e.contains("5th Monday of December"),
        "{e}"
    );
    assert!(fifth_monday.check(false, None).is_err());
    let saving = calendar(&format!("{run}RunPeriodControl:DaylightSavingTime, 2nd Sunday in March, 5th Monday in December;")).unwrap();
    let e = saving.saving_days(false, None).unwrap_err().to_string();
    assert!(e.contains("RunPeriodControl:DaylightSavingTime") && e.contains("'End Date'"), "{e}");
    let leap_run = "RunPeriod, R, 1, 1, 2020, 12, 31, 2020, , Yes, Yes, No;\nRunPeriodControl:SpecialDays, L, 5th Saturday in February, 1;";
    assert_eq!(calendar(leap_run).unwrap().day_types(true, None).unwrap()[59], t("Holiday"), "29 February 2020");
    assert!(calendar(leap_run).unwrap().check(false, None).is_err(), "no fifth Saturday in a 28-day February");
    let weather =
        WeatherDays::from_epw_text("w.epw", "L\nA\nB\nC\nHOLIDAYS/DAYLIGHT SAVINGS,No,0,0,1,Odd,5th Monday in December\n").unwrap();
    let e = calendar(run).unwrap().day_types(false, Some(&weather)).unwrap_err().to_string();
    assert!(e.contains("w.epw") && e.contains("HOLIDAYS/DAYLIGHT SAVINGS") && e.contains("holiday 1"), "{e}");
    let ignored = "RunPeriod, R, 1, 1, 2017, 12, 31, 2017, , No, Yes, No;\n";
    assert!(calendar(ignored).unwrap().check(false, Some(&weather)).is_ok(), "the weather file's holidays unused: EnergyPlus skips them");
}
