//! GeoJSON in WGS84 (RFC 7946): a city model's coordinates reprojected from its
//! `referenceSystem` to longitude and latitude, with the pure-Rust `proj4rs`.
//!
//! Owns which reference systems sunlit knows, by EPSG code, and their PROJ definitions (written
//! here from EPSG's parameters, so no database of definitions ships):
//! - **28992** (Amersfoort / RD New) and **7415** (RD New + NAP height, the 3D BAG's): the
//!   oblique stereographic projection on Bessel 1841, with EPSG's 7-parameter shift to WGS84
//!   (EPSG:15739; about 1 m, the accuracy of that transformation, not RDNAPTRANS's centimetres);
//! - **326zz / 327zz** (WGS 84 / UTM zone zz N / S) and **258zz** (ETRS89 / UTM zone zz N, zones
//!   28–38), ETRS89 taken as WGS84 (they differ by under a metre in Europe today).
//!
//! Any other system, or none, is an [`Error`] naming it; the GeoJSON then keeps the model's own
//! coordinates and says why ([`super::cadastre::roofs_geojson`]). Heights are left out: NAP and
//! other heights are not the WGS84 ellipsoid's.

use proj4rs::proj::Proj;

use crate::error::{Error, Result};

/// The systems sunlit reprojects, for messages.
pub const SUPPORTED: &str = "EPSG:28992, EPSG:7415, WGS 84 / UTM (EPSG:32601–32660, 32701–32760), ETRS89 / UTM (EPSG:25828–25838)";

/// A reprojection from a city model's system to WGS84 longitude and latitude.
pub struct ToWgs84 {
    from: Proj,
    to: Proj,
    /// The EPSG code it reprojects from.
    pub epsg: u32,
}

/// The EPSG code in a CityJSON `referenceSystem` (`https://www.opengis.net/def/crs/EPSG/0/7415`,
/// `urn:ogc:def:crs:EPSG::7415` or `EPSG:7415`).
pub fn epsg_code(reference_system: &str) -> Option<u32> {
    let upper = reference_system.to_ascii_uppercase();
    let at = upper.rfind("EPSG")?;
    let digits: String = upper[at + 4..]
        .trim_start_matches(|c: char| !c.is_ascii_digit())
        .rsplit(|c: char| !c.is_ascii_digit())
        .find(|s| !s.is_empty())
        .map(str::to_string)?;
    digits.parse().ok()
}

/// The PROJ definition of a supported EPSG code.
fn definition(epsg: u32) -> Option<String> {
    const RD: &str = "+proj=sterea +lat_0=52.15616055555555 +lon_0=5.38763888888889 +k=0.9999079 +x_0=155000 +y_0=463000 \
                      +ellps=bessel +towgs84=565.417,50.3319,465.552,-0.398957,0.343988,-1.8774,4.0725 +units=m +no_defs";
    match epsg {
        28992 | 7415 => Some(RD.to_string()),
        32601..=32660 => Some(format!("+proj=utm +zone={} +datum=WGS84 +units=m +no_defs", epsg - 32600)),
        32701..=32760 => Some(format!("+proj=utm +zone={} +south +datum=WGS84 +units=m +no_defs", epsg - 32700)),
        25828..=25838 => Some(format!("+proj=utm +zone={} +ellps=GRS80 +towgs84=0,0,0 +units=m +no_defs", epsg - 25800)),
        _ => None,
    }
}

impl ToWgs84 {
    /// The reprojection from `reference_system` (a CityJSON `referenceSystem`, `None` when the
    /// model names none); an error naming it when sunlit does not know it.
    pub fn new(reference_system: Option<&str>) -> Result<Self> {
        let unknown = |why: String| Error::argument("reference_system", format!("{why}; sunlit reprojects from {SUPPORTED}"));
        let Some(text) = reference_system else { return Err(unknown("the city model names no referenceSystem".into())) };
        let epsg = epsg_code(text).ok_or_else(|| unknown(format!("'{text}' names no EPSG code")))?;
        let def = definition(epsg).ok_or_else(|| unknown(format!("EPSG:{epsg} ('{text}') is not a system sunlit knows")))?;
        let proj = |d: &str| Proj::from_proj_string(d).map_err(|e| unknown(format!("EPSG:{epsg}: {e}")));
        Ok(Self { from: proj(&def)?, to: proj("+proj=longlat +datum=WGS84 +no_defs")?, epsg })
    }

    /// `[longitude, latitude]` in degrees of a point's easting and northing (m).
    pub fn lon_lat(&self, x: f64, y: f64) -> Result<[f64; 2]> {
        let mut p = (x, y, 0.0);
        proj4rs::transform::transform(&self.from, &self.to, &mut p)
            .map_err(|e| Error::argument("reference_system", format!("EPSG:{} cannot reproject ({x}, {y}): {e}", self.epsg)))?;
        Ok([p.0.to_degrees(), p.1.to_degrees()])
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// Metres between two WGS84 points (locally flat: fine for a metre's check).
    fn metres(a: [f64; 2], b: [f64; 2]) -> f64 {
        let lat = a[1].to_radians();
        let dx = (a[0] - b[0]).to_radians() * 6_378_137.0 * lat.cos();
        let dy = (a[1] - b[1]).to_radians() * 6_378_137.0;
        dx.hypot(dy)
    }

    #[test]
    fn the_rd_origin_lands_on_its_published_wgs84_coordinates() {
        // RD's origin (Amersfoort, x 155 000 m, y 463 000 m) in WGS84: 52.15517440° N,
        // 5.38720621° E, the reference point of the published RD↔WGS84 approximation
        // (Schreutelkamp & Strang van Hees); EPSG's 7-parameter shift is good to about a metre.
        for system in ["https://www.opengis.net/def/crs/EPSG/0/7415", "urn:ogc:def:crs:EPSG::28992", "EPSG:28992"] {
            let p = ToWgs84::new(Some(system)).unwrap().lon_lat(155_000.0, 463_000.0).unwrap();
            assert!(metres(p, [5.38720621, 52.15517440]) < 1.0, "{system}: {p:?}");
        }
    }

    #[test]
    fn utm_lands_on_a_published_point_and_on_its_central_meridian() {
        // The CN Tower, Toronto: 43°38′33.24″ N, 79°23′13.7″ W is UTM 17N 630 084 m E,
        // 4 833 438 m N (Wikipedia's worked example in "Universal Transverse Mercator").
        let cn = ToWgs84::new(Some("https://www.opengis.net/def/crs/EPSG/0/32617")).unwrap().lon_lat(630_084.0, 4_833_438.0).unwrap();
        let published = [-(79.0 + 23.0 / 60.0 + 13.7 / 3600.0), 43.0 + 38.0 / 60.0 + 33.24 / 3600.0];
        assert!(metres(cn, published) < 2.0, "{cn:?} against {published:?}");
        // The false easting lies on the central meridian; the false northing of the south on the
        // equator.
        let north = ToWgs84::new(Some("EPSG:25832")).unwrap().lon_lat(500_000.0, 5_000_000.0).unwrap();
        assert!((north[0] - 9.0).abs() < 1e-9, "{north:?}");
        let south = ToWgs84::new(Some("EPSG:32733")).unwrap().lon_lat(500_000.0, 10_000_000.0).unwrap();
        assert!((south[0] - 15.0).abs() < 1e-9 && south[1].abs() < 1e-9, "{south:?}");
    }

    #[test]
    fn unknown_systems_are_named() {
        let e = ToWgs84::new(Some("https://www.opengis.net/def/crs/EPSG/0/2056")).err().unwrap().to_string();
        assert!(e.contains("EPSG:2056") && e.contains("28992"), "{e}");
        let e = ToWgs84::new(None).err().unwrap().to_string();
        assert!(e.contains("names no referenceSystem"), "{e}");
        let e = ToWgs84::new(Some("local grid")).err().unwrap().to_string();
        assert!(e.contains("'local grid' names no EPSG code"), "{e}");
        assert_eq!(epsg_code("urn:ogc:def:crs:EPSG::7415"), Some(7415));
    }
}
