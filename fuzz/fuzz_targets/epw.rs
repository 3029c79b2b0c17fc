//! The EPW `LOCATION` reader: any text gives a checked site or an error.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sunlit::sun::location::Location;

fuzz_target!(|data: &[u8]| {
    if let Ok(site) = Location::from_epw_text("fuzz.epw", &String::from_utf8_lossy(data)) {
        // What is accepted is in range: the sun code relies on it.
        assert!((-90.0..=90.0).contains(&site.latitude) && (-180.0..=180.0).contains(&site.longitude));
        assert!((-12.0..=14.0).contains(&site.time_zone) && site.elevation.is_finite());
    }
});
