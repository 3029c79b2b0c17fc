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
    let geojson: Value = serde_json::from_str(&roofs_geojson(&city, &rows, "north").unwrap()).unwrap();
    let features = geojson["features"].as_array().unwrap();
    assert_eq!(features.len(), 1, "walls are not roofs");
    let rings = features[0]["geometry"]["coordinates"].as_array().unwrap();
    assert_eq!(rings.len(), 2, "the courtyard is a hole");
    // WGS84 (RFC 7946: no crs member): the corner at RD (85 120, 447 340), the translate added
    // back, where the published RD → WGS84 approximation puts it (within its metre).
    assert!(geojson.get("crs").is_none(), "{geojson}");
    assert!(geojson["sunlit"]["note"].as_str().unwrap().contains("EPSG:7415"), "{geojson}");
    let corner = [rings[0][0][0].as_f64().unwrap(), rings[0][0][1].as_f64().unwrap()];
    let truth = rd_to_wgs84_approximation(85_120.0, 447_340.0);
    let metres = ((corner[0] - truth[0]) * 111_320.0 * corner[1].to_radians().cos()).hypot((corner[1] - truth[1]) * 110_540.0);
    assert!(metres < 1.5, "{corner:?} against {truth:?}: {metres} m");
    // A model in a system sunlit does not know keeps its own coordinates, saying why.
    let swiss =
        crate::model::cityjson::City { reference_system: Some("https://www.opengis.net/def/crs/EPSG/0/2056".into()), ..city.clone() };
    let geojson: Value = serde_json::from_str(&roofs_geojson(&swiss, &rows, "north").unwrap()).unwrap();
    assert_eq!(geojson["features"][0]["geometry"]["coordinates"][0][0], serde_json::json!([85120.0, 447340.0]));
    assert_eq!(geojson["crs"]["properties"]["name"], "https://www.opengis.net/def/crs/EPSG/0/2056");
    assert!(geojson["sunlit"]["note"].as_str().unwrap().contains("EPSG:2056"), "{geojson}");
}

/// The published approximation of RD New → WGS84 (Schreutelkamp & Strang van Hees, "Benaderingsformules
/// voor de transformatie tussen RD- en WGS84-kaartcoördinaten"): polynomials about Amersfoort,
/// good to about a metre; `[lon, lat]`.
fn rd_to_wgs84_approximation(x: f64, y: f64) -> [f64; 2] {
    let (dx, dy) = ((x - 155_000.0) * 1e-5, (y - 463_000.0) * 1e-5);
    let k = [
        (0, 1, 3235.65389),
        (2, 0, -32.58297),
        (0, 2, -0.24750),
        (2, 1, -0.84978),
        (0, 3, -0.06550),
        (2, 2, -0.01709),
        (1, 0, -0.00738),
        (4, 0, 0.00530),
        (2, 3, -0.00039),
        (4, 1, 0.00033),
        (1, 1, -0.00012),
    ];
    let l = [
        (1, 0, 5260.52916),
        (1, 1, 105.94684),
        (1, 2, 2.45656),
        (3, 0, -0.81885),
        (1, 3, 0.05594),
        (3, 1, -0.05607),
        (0, 1, 0.01199),
        (3, 2, -0.00256),
        (1, 4, 0.00128),
        (0, 2, 0.00022),
        (2, 0, -0.00022),
        (5, 0, 0.00026),
    ];
    let sum = |terms: &[(i32, i32, f64)]| terms.iter().map(|&(p, q, c)| c * dx.powi(p) * dy.powi(q)).sum::<f64>() / 3600.0;
    [5.38720621 + sum(&l), 52.15517440 + sum(&k)]
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
