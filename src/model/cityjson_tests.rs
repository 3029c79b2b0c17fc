#![allow(clippy::unwrap_used)]
use super::*;

const BLOCK: &[u8] = include_bytes!("../../tests/city/block.city.json");

fn names(city: &City) -> Vec<&str> {
    city.surfaces.iter().map(|s| s.name.as_str()).collect()
}

#[test]
fn the_fixture_reads_with_its_transform_parts_holes_and_template() {
    let city = read_city("block.city.json", BLOCK, None).unwrap();
    assert_eq!(city.version, "2.0");
    assert_eq!(city.reference_system.as_deref(), Some("https://www.opengis.net/def/crs/EPSG/0/7415"));
    assert_eq!(city.offset, DVec3::new(85000.0, 447000.0, 0.0));
    // 10 courtyard surfaces (Solid), 7 of the house part's LoD 2.2 CompositeSurface (not its LoD
    // 1.2 solid), 6 of the tree's template.
    assert_eq!(city.surfaces.len(), 23, "{:?}", names(&city));
    let roof = city.surfaces.iter().find(|s| s.name == "NL.B.courtyard/RoofSurface/1").unwrap();
    assert_eq!(roof.rings.len(), 2, "the courtyard stays a hole");
    // Local coordinates: translate subtracted, scale applied (120 m east of the translate).
    assert!((roof.rings[0][0] - DVec3::new(120.0, 340.0, 10.0)).length() < 1e-9, "{}", roof.rings[0][0]);
    let part = city.surfaces.iter().find(|s| s.object == "NL.B.house.part").unwrap();
    assert_eq!(part.building.as_deref(), Some("NL.B.house"));
    assert_eq!(part.name, "NL.B.house.part/GroundSurface/0");
    let tree: Vec<&CitySurface> = city.surfaces.iter().filter(|s| s.object == "tree-1").collect();
    assert_eq!(tree.len(), 6);
    assert!(tree.iter().all(|s| s.building.is_none() && s.name.contains("/Surface/")));
    // The template's top at 6 m above the reference point (156, 356, 0).
    assert!((tree[1].rings[0][0] - DVec3::new(155.0, 355.0, 6.0)).length() < 1e-9, "{}", tree[1].rings[0][0]);
}

#[test]
fn lod_picks_the_geometry() {
    let city = read_city("block.city.json", BLOCK, Some("1.2")).unwrap();
    // Only the house part has LoD 1.2: its solid's six unlabelled faces.
    assert_eq!(city.surfaces.len(), 6, "{:?}", names(&city));
    assert!(city.surfaces.iter().all(|s| s.kind.is_none() && s.object == "NL.B.house.part"));
    let any_two = read_city("block.city.json", BLOCK, Some("2")).unwrap();
    assert_eq!(any_two.surfaces.len(), 23);
}

#[test]
fn the_model_holds_the_holes_and_marks_roofs_and_walls() {
    let city = read_city("block.city.json", BLOCK, None).unwrap();
    let model = city_model(&city, 0.0).unwrap();
    let k = city.surfaces.iter().position(|s| s.name == "NL.B.courtyard/RoofSurface/1").unwrap();
    let mesh = &model.meshes[k];
    let area: f64 = mesh
        .indices
        .chunks_exact(3)
        .map(|t| crate::geometry::triangle_area(&[0, 1, 2].map(|j| DVec3::from_array(mesh.positions[t[j] as usize].map(f64::from)))))
        .sum();
    assert!((area - (400.0 - 64.0)).abs() < 1e-6, "{area}");
    let marked: Vec<&str> = model.nodes.iter().filter(|n| n.marked).map(|n| n.name.as_str()).collect();
    assert_eq!(marked.len(), 9 + 6, "{marked:?}");
    assert!(marked.iter().all(|n| n.contains("/RoofSurface/") || n.contains("/WallSurface/")));
}

/// A minimal document around `objects`, `vertices` and a transform when given.
fn doc(version: &str, transform: bool, vertices: &str, objects: &str) -> String {
    let t = if transform { r#""transform":{"scale":[0.01,0.01,0.01],"translate":[0,0,0]},"# } else { "" };
    format!(r#"{{"type":"CityJSON","version":"{version}",{t}"CityObjects":{{{objects}}},"vertices":{vertices}}}"#)
}

const SQUARE: &str = "[[0,0,0],[100,0,0],[100,100,0],[0,100,0]]";

fn building(boundaries: &str, semantics: &str) -> String {
    format!(r#""b1":{{"type":"Building","geometry":[{{"type":"MultiSurface","lod":"2","boundaries":{boundaries}{semantics}}}]}}"#)
}

fn error(text: &str) -> String {
    read_city("c.city.json", text.as_bytes(), None).unwrap_err().to_string()
}

#[test]
fn bad_input_names_file_object_and_reason() {
    let ok = building("[[[0,1,2,3]]]", "");
    assert!(read_city("c.city.json", doc("2.0", true, SQUARE, &ok).as_bytes(), None).is_ok());
    assert_eq!(error(&doc("3.0", true, SQUARE, &ok)), "c.city.json: CityJSON version \"3.0\" is not read (read: 1.1, 2.0)");
    assert!(error(&doc("2.0", false, SQUARE, &ok)).starts_with("c.city.json: no \"transform\", yet the vertices are integers"));
    assert_eq!(
        error(&doc("2.0", true, SQUARE, &building("[[[0,1,2,7]]]", ""))),
        "c.city.json: CityObject 'b1': geometry 0: surface 0, ring 0: vertex index 7 is out of range (4 vertices)"
    );
    assert_eq!(
        error(&doc("2.0", true, SQUARE, &building("[[[0,1,0,1]]]", ""))),
        "c.city.json: CityObject 'b1': geometry 0: surface 0, ring 0: has 2 distinct vertices; a ring needs at least 3"
    );
    let pointing_nowhere = building("[[[0,1,2,3]]]", r#","semantics":{"surfaces":[{"type":"RoofSurface"}],"values":[4]}"#);
    assert_eq!(
        error(&doc("2.0", true, SQUARE, &pointing_nowhere)),
        "c.city.json: CityObject 'b1': geometry 0: surface 0: semantic value 4 points nowhere (1 semantic surfaces)"
    );
    // Finite as written, infinite once the offset (the smallest vertex) is taken off.
    let overflowing = "[[-1e308,0,0],[1e308,0,0],[1e308,1,0]]";
    assert_eq!(
        error(&doc("2.0", false, overflowing, &building("[[[0,1,2]]]", ""))),
        "c.city.json: CityObject 'b1': geometry 0: surface 0, ring 0: vertex index 1 is not finite once scaled and placed (check transform.scale and the coordinates)"
    );
    // Real-valued vertices need no transform (the smallest vertex is then the offset).
    let floats = "[[1000.5,2000,3],[1001.5,2000,3],[1001.5,2001,3]]";
    let city = read_city("c.city.json", doc("1.1", false, floats, &building("[[[0,1,2]]]", "")).as_bytes(), None).unwrap();
    assert_eq!(city.offset, DVec3::new(1000.5, 2000.0, 3.0));
    assert_eq!(city.surfaces[0].rings[0][1], DVec3::new(1.0, 0.0, 0.0));
}

#[test]
fn a_sequence_reads_its_features() {
    let header = r#"{"type":"CityJSON","version":"2.0","transform":{"scale":[0.01,0.01,0.01],"translate":[10,20,0]},"CityObjects":{},"vertices":[]}"#;
    let feature = |id: &str| {
        format!(
            r#"{{"type":"CityJSONFeature","id":"{id}","CityObjects":{{"{id}":{{"type":"Building","geometry":[{{"type":"MultiSurface","lod":"2","boundaries":[[[0,1,2]]],"semantics":{{"surfaces":[{{"type":"RoofSurface"}}],"values":[0]}}}}]}}}},"vertices":[[0,0,500],[100,0,500],[0,100,500]]}}"#
        )
    };
    let text = format!("{header}\n{}\n{}\n", feature("a"), feature("b"));
    let city = read_city("s.city.jsonl", text.as_bytes(), None).unwrap();
    assert_eq!(names(&city), ["a/RoofSurface/0", "b/RoofSurface/0"]);
    assert_eq!(city.surfaces[1].rings[0][1], DVec3::new(1.0, 0.0, 5.0));
    let bad = format!("{header}\n{{\"type\":\"Feature\"}}\n");
    assert_eq!(read_city("s.city.jsonl", bad.as_bytes(), None).unwrap_err().to_string(), "s.city.jsonl: line 2: not a CityJSONFeature");
}
