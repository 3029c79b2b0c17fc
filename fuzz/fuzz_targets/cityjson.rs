//! The CityJSON reader (a document or a CityJSONSeq), the city model's triangulation and the scene
//! built from it; and the cadastre's writer over what was read.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sunlit::model::cityjson::read_city;
use sunlit::model::{LoadOptions, load_bytes};

fuzz_target!(|data: &[u8]| {
    let _ = load_bytes(&[("fuzz.city.json".to_string(), data.to_vec())], &LoadOptions::default());
    let _ = load_bytes(&[("fuzz.city.jsonl".to_string(), data.to_vec())], &LoadOptions { lod: Some("2".into()), ..Default::default() });
    if let Ok(city) = read_city("fuzz.city.json", data, None) {
        let _ = sunlit::export::cadastre::cadastre_cityjson("fuzz.city.json", data, &city, &[]);
    }
});
