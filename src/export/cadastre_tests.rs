#![allow(clippy::unwrap_used)]
use super::*;

const BLOCK: &[u8] = include_bytes!("../../tests/city/block.city.json");

fn row(surface: &str, building: &str, total: f64) -> CadastreRow {
    CadastreRow {
        surface: surface.into(),
        building: building.into(),
        area: 10.0,
        direct: 1.0,
        sky_diffuse: 2.0,
        ground_reflected: 3.0,
        total,
        sun_hours: -0.0,
        mean_fraction: 0.5,
        usable_area: None,
    }
}

#[test]
fn valued_surfaces_get_semantic_surfaces_of_their_own() {
    let city = crate::model::cityjson::read_city("block.city.json", BLOCK, None).unwrap();
    // Two walls of the house part share one semantic object (index 1) with two others.
    let rows = [row("NL.B.house.part/WallSurface/1", "NL.B.house", 6.0), row("NL.B.house.part/WallSurface/3", "NL.B.house", 7.5)];
    let out = cadastre_cityjson("block.city.json", BLOCK, &city, &rows).unwrap();
    let doc: Value = serde_json::from_slice(&out).unwrap();
    let g = &doc["CityObjects"]["NL.B.house.part"]["geometry"][1];
    let values: Vec<Option<u64>> = g["semantics"]["values"].as_array().unwrap().iter().map(Value::as_u64).collect();
    assert_eq!(values, [Some(2), Some(4), Some(1), Some(5), Some(1), Some(0), Some(3)]);
    let surfaces = g["semantics"]["surfaces"].as_array().unwrap();
    assert_eq!(surfaces.len(), 6);
    assert_eq!(surfaces[4]["type"], "WallSurface");
    assert_eq!(surfaces[4]["total_kwh_m2"], 6.0);
    assert_eq!(surfaces[5]["total_kwh_m2"], 7.5);
    assert_eq!(surfaces[5]["sun_hours"].to_string(), "0.0", "never -0");
    assert!(surfaces[1].get("total_kwh_m2").is_none(), "the shared object is left as it was");
    // The rest of the model is as read.
    assert_eq!(doc["vertices"], serde_json::from_slice::<Value>(BLOCK).unwrap()["vertices"]);
}

#[test]
fn the_csv_and_roofs() {
    let city = crate::model::cityjson::read_city("block.city.json", BLOCK, None).unwrap();
    let rows = [row("NL.B.courtyard/RoofSurface/1", "NL.B.courtyard", 900.0), row("NL.B.courtyard/WallSurface/2", "NL.B.courtyard", 400.0)];
    let csv = cadastre_csv(&rows);
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(
        lines[0],
        "surface,building,area_m2,direct_kwh_m2,sky_diffuse_kwh_m2,ground_reflected_kwh_m2,total_kwh_m2,sun_hours,mean_sunlit_fraction"
    );
    assert_eq!(lines[1], "NL.B.courtyard/RoofSurface/1,NL.B.courtyard,10.0000,1.0000,2.0000,3.0000,900.0000,0.0000,0.500000");
    let geojson: Value = serde_json::from_str(&roofs_geojson(&city, &rows, "north")).unwrap();
    let features = geojson["features"].as_array().unwrap();
    assert_eq!(features.len(), 1, "walls are not roofs");
    let rings = features[0]["geometry"]["coordinates"].as_array().unwrap();
    assert_eq!(rings.len(), 2, "the courtyard is a hole");
    // Real coordinates: the translate added back.
    assert_eq!(rings[0][0], serde_json::json!([85120.0, 447340.0]));
    assert_eq!(geojson["crs"]["properties"]["name"], "https://www.opengis.net/def/crs/EPSG/0/7415");
}

#[test]
fn a_sequence_becomes_one_document_with_its_indices_moved() {
    let header =
        r#"{"type":"CityJSON","version":"2.0","transform":{"scale":[0.01,0.01,0.01],"translate":[0,0,0]},"CityObjects":{},"vertices":[]}"#;
    let feature = |id: &str| {
        format!(
            r#"{{"type":"CityJSONFeature","id":"{id}","CityObjects":{{"{id}":{{"type":"Building","geometry":[{{"type":"MultiSurface","lod":"2","boundaries":[[[0,1,2]]]}}]}}}},"vertices":[[0,0,0],[100,0,0],[0,100,0]]}}"#
        )
    };
    let text = format!("{header}\n{}\n{}\n", feature("a"), feature("b"));
    let doc = single_document("s.city.jsonl", text.as_bytes()).unwrap();
    assert_eq!(doc["type"], "CityJSON");
    assert_eq!(doc["vertices"].as_array().unwrap().len(), 6);
    assert_eq!(doc["CityObjects"]["a"]["geometry"][0]["boundaries"], serde_json::json!([[[0, 1, 2]]]));
    assert_eq!(doc["CityObjects"]["b"]["geometry"][0]["boundaries"], serde_json::json!([[[3, 4, 5]]]));
}
