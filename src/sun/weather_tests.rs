//! Tests of the EPW reader (a file of its own to keep `weather.rs` short).
#![allow(clippy::unwrap_used)]

use std::fmt::Write as _;

use super::*;

const DENVER: &str = "LOCATION,Denver Centennial,CO,USA,TMY3,724666,39.74,-105.18,-7.0,1793.0\r\nDESIGN CONDITIONS,0\r\n";

#[test]
fn epw_location_record_is_read() {
    let site = location_from_text("denver.epw", DENVER).unwrap();
    assert_eq!((site.latitude, site.longitude, site.time_zone, site.elevation), (39.74, -105.18, -7.0, 1793.0));
    assert_eq!(site.name, "Denver Centennial, CO, USA");
    // A byte-order mark and a placeholder state are tolerated.
    let site = location_from_text("x.epw", "\u{feff}LOCATION,Sydney,-,AUS,IWEC,947670,-33.95,151.18,10.0,3.0").unwrap();
    assert_eq!((site.latitude, site.name.as_str()), (-33.95, "Sydney, AUS"));
}

#[test]
fn epw_errors_name_file_and_reason() {
    let cases = [
        ("", "the first line is empty; an EPW weather file starts with its LOCATION record"),
        ("DESIGN CONDITIONS,0\nLOCATION,A,B,C,D,1,40,-105,-7,1600", "starts with 'DESIGN CONDITIONS,0'"),
        ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,-105.18", "has 8 fields, expected 10"),
        ("LOCATION,Denver,CO,USA,TMY3,724666,north,-105.18,-7.0,1793.0", "field 6 (latitude) is not a number: 'north'"),
        ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,,-7.0,1793.0", "field 7 (longitude) is not a number: ''"),
        ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,-105.18,MST,1793.0", "field 8 (time zone) is not a number: 'MST'"),
        ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,-105.18,-7.0,inf", "field 9 (elevation) is not a number: 'inf'"),
        ("LOCATION,Denver,CO,USA,TMY3,724666,139.74,-105.18,-7.0,1793.0", "latitude 139.74 is outside"),
        ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,-205.18,-7.0,1793.0", "longitude -205.18 is outside"),
        ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,-105.18,-17.0,1793.0", "time zone -17 is outside"),
        ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,-105.18,-7.0,12000", "elevation 12000 m is outside"),
    ];
    for (text, needle) in cases {
        let e = location_from_text("weather/denver.epw", text).unwrap_err().to_string();
        assert!(e.starts_with("weather/denver.epw: ") && e.contains(needle), "{text:?}: {e}");
    }
}

#[test]
fn epw_file_is_read_from_disk() {
    let dir = std::env::temp_dir().join(format!("sunlit-location-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("latin1.epw");
    // "Zürich" in Latin-1: not UTF-8, yet the numbers must still be read.
    let mut bytes = b"LOCATION,Z\xfcrich,-,CHE,IWEC,066600,47.38,8.57,1.0,556.0\r\n".to_vec();
    bytes.extend_from_slice(b"DESIGN CONDITIONS,0\r\n");
    std::fs::write(&path, bytes).unwrap();
    let site = location_from_epw(&path).unwrap();
    assert_eq!((site.latitude, site.longitude, site.time_zone, site.elevation), (47.38, 8.57, 1.0, 556.0));
    let missing = dir.join("missing.epw");
    let e = location_from_epw(&missing).unwrap_err();
    assert!(matches!(e, Error::Io { .. }) && e.to_string().contains("missing.epw"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An EPW of `records` hourly records with the given DNI, DHI, GHI and albedo fields (text).
fn epw(records: usize, dni: &str, dhi: &str, ghi: &str, albedo: &str) -> String {
    let mut text = String::from("LOCATION,Test,-,X,Y,0,40,-105,-7,0\n");
    for header in ["DESIGN CONDITIONS,0", "TYPICAL/EXTREME PERIODS,0", "GROUND TEMPERATURES,0", "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0"] {
        text.push_str(header);
        text.push('\n');
    }
    text.push_str("COMMENTS 1,\nCOMMENTS 2,\nDATA PERIODS,1,1,Data,Sunday,1/1,12/31\n");
    for h in 0..records {
        let (day, hour) = (h / 24 + 1, h % 24 + 1);
        let (month, dom) = crate::year::samples::month_day(day as u32);
        let _ = writeln!(
            text,
            "1999,{month},{dom},{hour},60,x,10,5,50,80000,0,1000,300,{ghi},{dni},{dhi},0,0,0,0,0,0,0,0,0,0,9,0,0,0,0,0,{albedo},0,0"
        );
    }
    text
}

#[test]
fn epw_solar_columns_are_read() {
    let weather = Weather::from_epw_text("w.epw", &epw(8760, "612", "101", "455", "0.31")).unwrap();
    let timesteps = Timesteps::new(4).unwrap();
    let expected = Hour { dni: 612.0, dhi: 101.0, ghi: 455.0, albedo: 0.31 };
    assert_eq!((weather.at(timesteps, 0), weather.at(timesteps, 35_039)), (expected, expected));
    assert_eq!(weather.location.latitude, 40.0);
    // 999 marks a missing albedo: the default.
    let missing = Weather::from_epw_text("w.epw", &epw(8760, "1", "1", "1", "999")).unwrap();
    assert_eq!(missing.at(timesteps, 5).albedo, DEFAULT_ALBEDO);
    // A given albedo replaces the file's; outside 0..=1 it is refused naming `albedo`.
    assert_eq!(weather.clone().with_albedo(0.5).unwrap().at(timesteps, 9).albedo, 0.5);
    let e = weather.with_albedo(1.5).unwrap_err().to_string();
    assert!(e.contains("albedo") && e.contains("1.5 is outside 0..=1"), "{e}");
}

#[test]
fn each_row_takes_its_hour_and_leap_years_line_up() {
    let mut text = epw(8760, "0", "0", "0", "0.2");
    // Make each record's DNI its hour index, so the row → hour map is visible.
    let lines: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i < 8 {
                return l.to_string();
            }
            let mut f: Vec<String> = l.split(',').map(String::from).collect();
            f[14] = ((i - 8) % 1000).to_string();
            f.join(",")
        })
        .collect();
    text = lines.join("\n");
    let weather = Weather::from_epw_text("w.epw", &text).unwrap();
    let n4 = Timesteps::new(4).unwrap();
    assert_eq!(weather.at(n4, 4 * 30 + 3).dni, 30.0, "row 123 at N = 4 is hour 30");
    // A leap-year schedule repeats 28 February (day 59) on 29 February and shifts the rest by a day.
    let leap = n4.leap_year(true);
    let feb29 = 59 * 24 * 4;
    assert_eq!(weather.at(leap, feb29).dni, weather.at(n4, feb29 - 24 * 4).dni);
    assert_eq!(weather.at(leap, feb29 + 24 * 4).dni, weather.at(n4, feb29).dni);
}

/// EnergyPlus 25.2's direct normal irradiance at Timestep 4 (`Site Direct Solar Radiation Rate
/// per Area`, Chicago TMY3, 9 February 16:15–17:00, hours of 747, 490 and 41 W/m²): 554.25,
/// 490, 377.75, 265.5. Timestep 1 averages an hour with the next; the last hour has none after.
#[test]
fn dni_is_interpolated_between_hour_middles_as_energyplus_does() {
    let mut text = epw(8760, "0", "0", "0", "0.2");
    let hour = (31 + 8) * 24 + 16; // 9 February, the record ending 17:00
    for (h, dni) in [(hour - 1, "747"), (hour, "490"), (hour + 1, "41"), (8759, "100")] {
        let line = text.lines().nth(8 + h).unwrap().to_string();
        let mut f: Vec<&str> = line.split(',').collect();
        f[14] = dni;
        text = text.replacen(&line, &f.join(","), 1);
    }
    let weather = Weather::from_epw_text("w.epw", &text).unwrap();
    let n4 = Timesteps::new(4).unwrap();
    let got: Vec<f64> = (0..4).map(|ts| weather.dni_as_energyplus(n4, hour * 4 + ts)).collect();
    assert_eq!(got, [554.25, 490.0, 377.75, 265.5]);
    assert_eq!(weather.dni_as_energyplus(Timesteps::new(1).unwrap(), hour), 490.0, "one timestep an hour: the hour held");
    assert_eq!(weather.dni_as_energyplus(n4, 8759 * 4 + 3), 100.0);
}

fn short_first_record() -> String {
    let text = epw(8760, "5", "5", "5", "0.2");
    let mut lines: Vec<&str> = text.lines().collect();
    lines[8] = "1999,1,1,1,60,x,10,5,50,80000,0,1000,300,400";
    lines.join("\n")
}

#[test]
fn bad_epw_records_name_file_line_and_field() {
    let cases = [
        (epw(100, "5", "5", "5", "0.2"), "w.epw: 100 hourly data records after the 8 header lines; an EPW year has 8760"),
        (epw(8760, "9999", "5", "5", "0.2"), "w.epw: line 9: direct normal irradiance (field 15) is missing (9999)"),
        (epw(8760, "lots", "5", "5", "0.2"), "w.epw: line 9: direct normal irradiance (field 15) 'lots' is not a number"),
        (epw(8760, "-3", "5", "5", "0.2"), "w.epw: line 9: direct normal irradiance (field 15) -3 is negative"),
        (epw(8760, "5", "9999", "5", "0.2"), "w.epw: line 9: diffuse horizontal irradiance (field 16) is missing (9999)"),
        (epw(8760, "5", "-1", "5", "0.2"), "w.epw: line 9: diffuse horizontal irradiance (field 16) -1 is negative"),
        (
            epw(8760, "5", "5", "1600", "0.2"),
            "w.epw: line 9: global horizontal irradiance (field 14) 1600 W/m² is beyond the physical bound",
        ),
        (epw(8760, "2000", "5", "5", "0.2"), "w.epw: line 9: direct normal irradiance (field 15) 2000 W/m² is beyond"),
        (epw(8760, "5", "5", "5", "1.4"), "w.epw: line 9: albedo (field 33) 1.4 is outside 0..=1"),
        (short_first_record(), "w.epw: line 9: 14 fields, expected at least 16"),
    ];
    for (text, needle) in cases {
        let e = Weather::from_epw_text("w.epw", &text).unwrap_err().to_string();
        assert!(e.starts_with(needle), "{needle}: {e}");
    }
}
