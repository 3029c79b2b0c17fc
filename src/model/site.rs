//! An EnergyPlus model's own `Site:Location`: where the model says it stands.
//!
//! Owns reading it (IDF or epJSON, fields Name, Latitude, Longitude, Time Zone, Elevation, with
//! EnergyPlus's defaults for blank fields: 0° N, 0° E, UTC, 0 m), so a model needs no weather file
//! or explicit location to be counted where EnergyPlus would simulate it. EnergyPlus itself
//! replaces it with the weather file's location in a weather-file run; so does sunlit when a
//! weather file is given.

use super::idf::IdfObject;
use crate::error::{Error, Result};
use crate::sun::location::Location;

/// The model's `Site:Location`, if it has one; an error names the object and the field.
pub fn site_location(file: &str, objects: &[IdfObject]) -> Result<Option<Location>> {
    let Some(o) = objects.iter().find(|o| o.is("Site:Location")) else { return Ok(None) };
    let number = |i: usize, what: &str| -> Result<f64> {
        let text = o.field(i).trim();
        if text.is_empty() {
            return Ok(0.0);
        }
        text.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| Error::object(file, o.label(), format!("field {} ({what}) '{text}' is not a number", i + 1)))
    };
    let (latitude, longitude, time_zone) = (number(1, "Latitude")?, number(2, "Longitude")?, number(3, "Time Zone")?);
    let mut location = Location::new(latitude, longitude, time_zone).map_err(|e| Error::object(file, o.label(), e.to_string()))?;
    location.elevation = number(4, "Elevation")?;
    location.name = o.name().unwrap_or("").to_string();
    Ok(Some(location))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::idf::parse_idf;

    #[test]
    fn site_location_is_read_with_its_defaults_and_errors() {
        let text = "Version,25.2;\nSite:Location,\n  Chicago Ohare Intl Ap IL USA WMO=725300,  !- Name\n  41.99, -87.91, -6.00, 205.00;\n";
        let l = site_location("m.idf", &parse_idf("m.idf", text).unwrap()).unwrap().unwrap();
        assert_eq!((l.latitude, l.longitude, l.time_zone, l.elevation), (41.99, -87.91, -6.0, 205.0));
        assert_eq!(l.name, "Chicago Ohare Intl Ap IL USA WMO=725300");
        assert!(site_location("m.idf", &parse_idf("m.idf", "Version,25.2;\n").unwrap()).unwrap().is_none());
        let blank = site_location("m.idf", &parse_idf("m.idf", "Site:Location,Nowhere;\n").unwrap()).unwrap().unwrap();
        assert_eq!((blank.latitude, blank.longitude, blank.time_zone), (0.0, 0.0, 0.0));
        let e = site_location("m.idf", &parse_idf("m.idf", "Site:Location,X,north,1,1;\n").unwrap()).unwrap_err().to_string();
        assert!(e.contains("Site:Location 'X'") && e.contains("Latitude") && e.contains("'north'"), "{e}");
        let e = site_location("m.idf", &parse_idf("m.idf", "Site:Location,X,95,1,1;\n").unwrap()).unwrap_err().to_string();
        assert!(e.contains("Site:Location 'X'") && e.contains("95"), "{e}");
    }
}
