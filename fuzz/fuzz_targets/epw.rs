//! The EPW reader (`sun::weather`): any text gives a checked site and year of solar data, or an
//! error.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sunlit::sun::weather::{Weather, location_from_text};
use sunlit::year::samples::Timesteps;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(site) = location_from_text("fuzz.epw", &text) {
        // What is accepted is in range: the sun code relies on it.
        assert!((-90.0..=90.0).contains(&site.latitude) && (-180.0..=180.0).contains(&site.longitude));
        assert!((-12.0..=14.0).contains(&site.time_zone) && site.elevation.is_finite());
    }
    if let (Ok(weather), Ok(hourly)) = (Weather::from_epw_text("fuzz.epw", &text), Timesteps::new(1)) {
        // Accepted radiation is physical: the irradiance sums rely on it.
        for row in [0, 4_000, 8_759] {
            let hour = weather.at(hourly, row);
            assert!([hour.dni, hour.dhi, hour.ghi].iter().all(|v| v.is_finite() && *v >= 0.0));
            assert!((0.0..=1.0).contains(&hour.albedo));
        }
    }
});
