//! Tests of the geometry rules and the meshing against hand-placed buildings.

use super::super::epjson::parse_epjson;
use super::super::idf::parse_idf;
use super::frame::azimuth_tilt;
use super::mesh::triangulate;
use super::*;

/// One zone (origin (2, 3, 0.5), relative north 15°) in a building turned 30°: every zone
/// point turns 45° in all. Expected world coordinates are those EnergyPlus 25.2 writes for
/// this model (Output:Surfaces:List, DetailsWithVertices; eio rounds to 0.01 m).
const MODEL: &str = "Version,25.2;
Building,Test Bldg,30,Suburbs,0.04,0.4,FullExterior,25,6;
GlobalGeometryRules,UpperLeftCorner,Counterclockwise,Relative,Relative,Relative;
Zone,Zone One,15,2,3,0.5;
Material,M1,Smooth,0.1,1.0,1000,1000;
BuildingSurface:Detailed,Wall S,Wall,C1,Zone One,,Outdoors,,SunExposed,WindExposed,autocalculate,4,
  0,0,3, 0,0,0, 10,0,0, 10,0,3;
BuildingSurface:Detailed,Wall E,Wall,C1,Zone One,,Outdoors,,SunExposed,WindExposed,autocalculate,4,
  10,0,3, 10,0,0, 10,8,0, 10,8,3;
BuildingSurface:Detailed,Wall N,Wall,C1,Zone One,,Outdoors,,SunExposed,WindExposed,autocalculate,4,
  10,8,3, 10,8,0, 0,8,0, 0,8,3;
BuildingSurface:Detailed,Wall W,Wall,C1,Zone One,,Outdoors,,SunExposed,WindExposed,autocalculate,4,
  0,8,3, 0,8,0, 0,0,0, 0,0,3;
BuildingSurface:Detailed,Roof,Roof,C1,Zone One,,Outdoors,,SunExposed,WindExposed,autocalculate,4,
  0,8,3, 0,0,3, 10,0,3, 10,8,3;
BuildingSurface:Detailed,Floor,Floor,C1,Zone One,,Ground,,NoSun,NoWind,autocalculate,4,
  0,0,0, 0,8,0, 10,8,0, 10,0,0;
FenestrationSurface:Detailed,Win S,Window,WIN,Wall S,,autocalculate,,1,4,
  2,0,2.5, 2,0,1, 8,0,1, 8,0,2.5;
Shading:Building:Detailed,Overhang B,,4,
  1,-1,2.8, 1,0,2.8, 9,0,2.8, 9,-1,2.8;
";

fn read(text: &str) -> Building {
    read_building("m.idf", &parse_idf("m.idf", text).unwrap()).unwrap()
}

fn read_err(text: &str) -> String {
    match parse_idf("m.idf", text).and_then(|o| read_building("m.idf", &o)) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

fn assert_vertices(b: &Building, name: &str, expected: &[[f64; 3]], tolerance: f64) {
    let s = b.surface(name).unwrap_or_else(|| panic!("no surface {name}"));
    assert_eq!(s.vertices.len(), expected.len(), "{name}");
    for (v, e) in s.vertices.iter().zip(expected) {
        assert!((*v - DVec3::from(*e)).abs().max_element() <= tolerance, "{name}: {:?} vs {e:?}", s.vertices);
    }
}

fn net_area(triangles: &[[DVec3; 3]]) -> f64 {
    triangles.iter().map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()).sum()
}

#[test]
fn relative_coordinates_turn_by_zone_and_building_north() {
    let b = read(MODEL);
    assert_eq!((b.version.as_deref(), b.north_axis), (Some("25.2"), 30.0));
    // By hand: the zone origin (2, 3) turned 30° clockwise is (2 cos30 + 3 sin30, −2 sin30 + 3 cos30).
    let cos30 = 30f64.to_radians().cos();
    let origin = [2.0 * cos30 + 1.5, -1.0 + 3.0 * cos30, 0.5];
    // (10, 0) turns 45° about the zone origin: + 10 (cos45, −sin45).
    let s = 10.0 * 45f64.to_radians().cos();
    let corner = [origin[0] + s, origin[1] - s, 0.5];
    assert_vertices(&b, "Wall S", &[[origin[0], origin[1], 3.5], origin, corner, [corner[0], corner[1], 3.5]], 1e-9);
    // EnergyPlus's own numbers.
    assert_vertices(&b, "Roof", &[[8.89, 7.25, 3.5], [3.23, 1.60, 3.5], [10.30, -5.47, 3.5], [15.96, 0.18, 3.5]], 0.0051);
    assert_vertices(&b, "Win S", &[[4.65, 0.18, 3.0], [4.65, 0.18, 1.5], [8.89, -4.06, 1.5], [8.89, -4.06, 3.0]], 0.0051);
    // Building shading turns with the building but has no zone origin.
    assert_vertices(&b, "Overhang B", &[[0.37, -1.37, 2.8], [0.87, -0.50, 2.8], [7.79, -4.50, 2.8], [7.29, -5.37, 2.8]], 0.0051);
    let (azimuth, tilt) = azimuth_tilt(&b.surface("Wall S").unwrap().vertices);
    assert!((azimuth - 225.0).abs() < 1e-9 && (tilt - 90.0).abs() < 1e-9, "{azimuth} {tilt}");
}

#[test]
fn receivers_windows_and_skipped_classes() {
    let b = read(MODEL);
    assert_eq!(b.receiver_names(), ["Wall S", "Wall E", "Wall N", "Wall W", "Roof", "Win S"]);
    let win = b.surface("WIN S").unwrap();
    assert_eq!((win.kind.as_str(), win.base.as_deref(), win.outside_boundary.as_str()), ("Window", Some("Wall S"), "Outdoors"));
    assert!(win.receiver && !b.surface("Floor").unwrap().receiver && !b.surface("Overhang B").unwrap().receiver);
    assert_eq!(b.skipped, ["Material"]);
    assert!(b.warnings.is_empty(), "{:?}", b.warnings);
    // The wall's receiver is its net area: 10 × 3 less the 6 × 1.5 window (EnergyPlus: 21.00).
    let holes = b.holes();
    let wall = b.surfaces.iter().position(|s| s.name == "Wall S").unwrap();
    assert_eq!(holes[&wall].len(), 1);
    assert!((net_area(&triangulate(&b.surfaces[wall], &holes[&wall])) - 21.0).abs() < 1e-9);
    assert!((net_area(&triangulate(win, &[])) - 9.0).abs() < 1e-9);
}

#[test]
fn scene_receivers_face_outwards() {
    let b = read(MODEL);
    let mut builder = SceneBuilder::new();
    b.add_to(&mut builder).unwrap();
    let scene = builder.build().unwrap();
    let names: Vec<&str> = scene.receivers.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, b.receiver_names());
    // South wall: azimuth 180 turned by 15° + 30° → facing 225°, normal (sin 225°, cos 225°, 0).
    let (_, wall) = scene.receiver("Wall S").unwrap();
    let facing = DVec3::new(225f64.to_radians().sin(), 225f64.to_radians().cos(), 0.0);
    assert!(wall.normal.distance(facing) < 1e-6, "{:?}", wall.normal);
    assert!((wall.area - 21.0).abs() < 1e-4, "{}", wall.area);
    let (_, window) = scene.receiver("Win S").unwrap();
    assert!(window.normal.distance(facing) < 1e-6 && (window.area - 9.0).abs() < 1e-4);
    let (_, roof) = scene.receiver("Roof").unwrap();
    assert!(roof.normal.distance(DVec3::Z) < 1e-6);
    let (_, east) = scene.receiver("Wall E").unwrap();
    let east_facing = DVec3::new(135f64.to_radians().sin(), 135f64.to_radians().cos(), 0.0);
    assert!(east.normal.distance(east_facing) < 1e-6, "{:?}", east.normal);
    // Floor and overhang cast shadows: 6 receivers, all 8 surfaces drawn.
    assert_eq!(scene.receivers.len(), 6);
    assert_eq!(scene.world_triangles().filter(|(_, id)| id.is_none()).count(), 2 + 2);
}

#[test]
fn epjson_gives_the_same_surfaces() {
    // Sun Exposure as the IDF gives it (the ground floor NoSun).
    let wall = |name: &str, kind: &str, boundary: &str, v: &str| {
        let sun = if boundary == "Ground" { "NoSun" } else { "SunExposed" };
        format!(
            r#""{name}": {{"surface_type": "{kind}", "construction_name": "C1", "zone_name": "Zone One",
            "outside_boundary_condition": "{boundary}", "sun_exposure": "{sun}", "number_of_vertices": 4, "vertices": [{v}]}}"#
        )
    };
    let v =
        |p: [f64; 3]| format!(r#"{{"vertex_x_coordinate": {}, "vertex_y_coordinate": {}, "vertex_z_coordinate": {}}}"#, p[0], p[1], p[2]);
    let vs = |ps: [[f64; 3]; 4]| ps.map(v).join(", ");
    let surfaces = [
        wall("Wall S", "Wall", "Outdoors", &vs([[0., 0., 3.], [0., 0., 0.], [10., 0., 0.], [10., 0., 3.]])),
        wall("Wall E", "Wall", "Outdoors", &vs([[10., 0., 3.], [10., 0., 0.], [10., 8., 0.], [10., 8., 3.]])),
        wall("Wall N", "Wall", "Outdoors", &vs([[10., 8., 3.], [10., 8., 0.], [0., 8., 0.], [0., 8., 3.]])),
        wall("Wall W", "Wall", "Outdoors", &vs([[0., 8., 3.], [0., 8., 0.], [0., 0., 0.], [0., 0., 3.]])),
        wall("Roof", "Roof", "Outdoors", &vs([[0., 8., 3.], [0., 0., 3.], [10., 0., 3.], [10., 8., 3.]])),
        wall("Floor", "Floor", "Ground", &vs([[0., 0., 0.], [0., 8., 0.], [10., 8., 0.], [10., 0., 0.]])),
    ];
    let text = format!(
        r#"{{
  "Version": {{"Version 1": {{"version_identifier": "25.2"}}}},
  "Building": {{"Test Bldg": {{"north_axis": 30}}}},
  "GlobalGeometryRules": {{"GlobalGeometryRules 1": {{"starting_vertex_position": "UpperLeftCorner",
  "vertex_entry_direction": "Counterclockwise", "coordinate_system": "Relative"}}}},
  "Zone": {{"Zone One": {{"direction_of_relative_north": 15, "x_origin": 2, "y_origin": 3, "z_origin": 0.5}}}},
  "Material": {{"M1": {{"thickness": 0.1}}}},
  "BuildingSurface:Detailed": {{ {} }},
  "FenestrationSurface:Detailed": {{"Win S": {{"surface_type": "Window", "construction_name": "WIN",
  "building_surface_name": "Wall S", "number_of_vertices": 4,
  "vertex_1_x_coordinate": 2, "vertex_1_y_coordinate": 0, "vertex_1_z_coordinate": 2.5,
  "vertex_2_x_coordinate": 2, "vertex_2_y_coordinate": 0, "vertex_2_z_coordinate": 1,
  "vertex_3_x_coordinate": 8, "vertex_3_y_coordinate": 0, "vertex_3_z_coordinate": 1,
  "vertex_4_x_coordinate": 8, "vertex_4_y_coordinate": 0, "vertex_4_z_coordinate": 2.5}}}},
  "Shading:Building:Detailed": {{"Overhang B": {{"number_of_vertices": 4,
  "vertices": [{}]}}}}
}}"#,
        surfaces.join(",\n"),
        vs([[1., -1., 2.8], [1., 0., 2.8], [9., 0., 2.8], [9., -1., 2.8]])
    );
    let from_json = read_building("m.epJSON", &parse_epjson("m.epJSON", &text).unwrap()).unwrap();
    let from_idf = read(MODEL);
    let strip = |b: &Building| b.surfaces.iter().map(|s| EpSurface { line: 0, ..s.clone() }).collect::<Vec<_>>();
    assert_eq!(strip(&from_json), strip(&from_idf));
    assert_eq!(from_json.receiver_names(), from_idf.receiver_names());
    assert_eq!(from_json.skipped, ["Material"]);
    assert_eq!(from_json.surface("Win S").unwrap().line, 20);
}

#[test]
fn clockwise_and_other_corners_are_reordered() {
    let llc = MODEL
        .replace("UpperLeftCorner,Counterclockwise", "LowerLeftCorner,Clockwise")
        // Lower-left first, then clockwise seen from outside: up, right, down.
        .replace("0,0,3, 0,0,0, 10,0,0, 10,0,3;", "0,0,0, 0,0,3, 10,0,3, 10,0,0;");
    let (a, b) = (read(MODEL), read(&llc));
    assert_eq!(a.surface("Wall S").unwrap().vertices, b.surface("Wall S").unwrap().vertices);
}

#[test]
fn world_coordinates_ignore_zone_origin_and_north_axis() {
    let b = read(&MODEL.replace("Counterclockwise,Relative,", "Counterclockwise,World,"));
    assert_eq!(b.north_axis, 30.0);
    assert_vertices(&b, "Wall S", &[[0., 0., 3.], [0., 0., 0.], [10., 0., 0.], [10., 0., 3.]], 0.0);
    assert_vertices(&b, "Overhang B", &[[1., -1., 2.8], [1., 0., 2.8], [9., 0., 2.8], [9., -1., 2.8]], 0.0);
    // Appendix G rotates even World coordinates (EnergyPlus 25.2 agrees).
    let g = read(
        &MODEL.replace("Counterclockwise,Relative,", "Counterclockwise,World,").replace("Material,", "Compliance:Building,90;\nMaterial,"),
    );
    assert_vertices(&g, "Wall S", &[[0., 0., 3.], [0., 0., 0.], [0., -10., 0.], [0., -10., 3.]], 1e-9);
}

/// Rectangular surfaces, simple windows, overhangs and fins against EnergyPlus 25.2.
#[test]
#[allow(clippy::approx_constant)] // -3.14 below is EnergyPlus's coordinate, not π.
fn simple_surfaces_match_energyplus() {
    let text = format!(
        "{MODEL}Wall:Exterior,Ext Wall,C1,Zone One,,200,90,12,0,0,4,3;
Roof,Ext Roof,C1,Zone One,,180,20,12,0,3,4,2;
Window,Ext Win,WIN,Ext Wall,,1,0.5,1,2,1;
Window,Win E,WIN,Wall E,,1,1.5,0.8,2,1.2;
Window,Sky,WIN,Roof,,1,2,3,1.5,1;
Door,Door N,C1,Wall N,1,3,0,1,2;
Shading:Overhang,OH,Win E,0.2,90,0.3,0.4,0.6;
Shading:Overhang:Projection,OHP,Ext Win,0.1,80,0.2,0.1,0.5;
Shading:Fin,Fins,Win S,0.1,0.2,0.3,90,0.5,0.2,0.1,0.2,70,0.4;
Shading:Zone:Detailed,Zone Fin,Wall S,,4,10,0,3,10,-1,3,10,-1,0,10,0,0;
Shading:Site,Site Simple,150,90,-5,-5,0,3,4;
Shading:Building,Bldg Simple,150,90,-5,-5,0,3,4;
"
    );
    let b = read(&text);
    let expected: [(&str, [[f64; 3]; 4]); 13] = [
        ("Ext Wall", [[11.72, -6.89, 3.5], [11.72, -6.89, 0.5], [13.41, -10.51, 0.5], [13.41, -10.51, 3.5]]),
        ("Ext Roof", [[13.05, -5.56, 4.18], [11.72, -6.89, 3.5], [14.55, -9.72, 3.5], [15.87, -8.39, 4.18]]),
        ("Ext Win", [[11.93, -7.34, 2.5], [11.93, -7.34, 1.5], [12.77, -9.15, 1.5], [12.77, -9.15, 2.5]]),
        ("Win E", [[11.36, -4.41, 2.5], [11.36, -4.41, 1.3], [12.78, -3.0, 1.3], [12.78, -3.0, 2.5]]),
        ("Sky", [[7.47, 3.01, 3.5], [6.77, 2.31, 3.5], [7.83, 1.24, 3.5], [8.54, 1.95, 3.5]]),
        ("Door N", [[13.84, 2.31, 2.5], [13.84, 2.31, 0.5], [13.13, 3.01, 0.5], [13.13, 3.01, 2.5]]),
        ("OH", [[11.58, -5.05, 2.7], [11.15, -4.62, 2.7], [13.06, -2.72, 2.7], [13.49, -3.14, 2.7]]),
        ("OHP", [[11.40, -7.37, 2.69], [11.84, -7.16, 2.6], [12.82, -9.24, 2.6], [12.37, -9.45, 2.69]]),
        ("Fins Left", [[4.58, 0.25, 3.2], [4.58, 0.25, 1.2], [4.22, -0.099, 1.2], [4.22, -0.099, 3.2]]),
        ("Fins Right", [[9.03, -4.2, 3.1], [9.03, -4.2, 1.3], [8.86, -4.56, 1.3], [8.86, -4.56, 3.1]]),
        ("Zone Fin", [[10.30, -5.47, 3.5], [9.60, -6.18, 3.5], [9.60, -6.18, 0.5], [10.30, -5.47, 0.5]]),
        ("Site Simple", [[-5.0, -5.0, 4.0], [-5.0, -5.0, 0.0], [-2.4, -3.5, 0.0], [-2.4, -3.5, 4.0]]),
        ("Bldg Simple", [[-6.83, -1.83, 4.0], [-6.83, -1.83, 0.0], [-3.83, -1.83, 0.0], [-3.83, -1.83, 4.0]]),
    ];
    for (name, vertices) in expected {
        assert_vertices(&b, name, &vertices, 0.0051);
    }
    let receivers = b.receiver_names();
    assert!(["Ext Wall", "Ext Roof", "Ext Win", "Sky", "Door N"].iter().all(|n| receivers.iter().any(|r| r == n)), "{receivers:?}");
    assert!(b.warnings.is_empty(), "{:?}", b.warnings);
    let mut builder = SceneBuilder::new();
    b.add_to(&mut builder).unwrap();
    let scene = builder.build().unwrap();
    assert!((scene.receiver("Roof").unwrap().1.area - (80.0 - 1.5)).abs() < 1e-4);
    assert!((scene.receiver("Wall N").unwrap().1.area - (30.0 - 2.0)).abs() < 1e-4);
}

#[test]
fn older_versions_shift_fields() {
    // 9.5: no Space Name; 8.9: fenestration also has a Shading Control Name.
    let old = MODEL
        .replace("Version,25.2;", "Version,8.9;")
        .replace("C1,Zone One,,", "C1,Zone One,")
        .replace(",autocalculate,,1,4,", ",autocalculate,,,1,4,");
    let b = read(&old);
    assert_eq!(
        b.surfaces.iter().map(|s| &s.vertices).collect::<Vec<_>>(),
        read(MODEL).surfaces.iter().map(|s| &s.vertices).collect::<Vec<_>>()
    );
    assert_eq!(IddLayout::from_version(Some("9.5.0")), IddLayout { space_name: false, shading_control: false });
    assert_eq!(IddLayout::from_version(Some("9.6")), IddLayout { space_name: true, shading_control: false });
    assert_eq!(IddLayout::from_version(None), IddLayout::from_version(Some("25.2")));
}

#[test]
fn non_planar_surfaces_warn_with_their_deviation() {
    let b = read(&MODEL.replace("10,8,3, 10,8,0, 0,8,0, 0,8,3;", "10,8,3, 10,8,0, 0,8,0, 0,8.1,3;"));
    let warning = b.warnings.iter().find(|w| w.contains("Wall N")).unwrap();
    assert!(warning.contains("line 10") && warning.contains("not planar") && warning.contains("0.0250 m"), "{warning}");
    let mut builder = SceneBuilder::new();
    b.add_to(&mut builder).unwrap();
    assert!(builder.build().unwrap().receiver("Wall N").is_some(), "flattened into one receiver");
}

#[test]
fn errors_name_object_and_line() {
    let cases = [
        (
            "10,8,3, 10,8,0, 0,8,0, 0,8,3;",
            "10,8,3, 10,8,0, 0,8,0;",
            "BuildingSurface:Detailed 'Wall N' (line 10): Number of Vertices is 4 but 3 vertices are given",
        ),
        (
            "10,8,3, 10,8,0, 0,8,0, 0,8,3;",
            "10,8,3, 10,8,0, 0,8,0, 0,8;",
            "'Wall N' (line 10): has 11 vertex coordinates, not x, y, z triples",
        ),
        (
            "10,8,3, 10,8,0, 0,8,0, 0,8,3;",
            "10,8,3, 10,8,0, 0,eight,0, 0,8,3;",
            "'Wall N' (line 10): vertex 3 y-coordinate 'eight' is not a number",
        ),
        (
            "Wall S,,autocalculate,,1,4,",
            "Wall Q,,autocalculate,,1,4,",
            "FenestrationSurface:Detailed 'Win S' (line 18): base surface 'Wall Q' does not exist",
        ),
        (
            "Wall W,Wall,C1,Zone One,",
            "Wall W,Wall,C1,Zone Two,",
            "BuildingSurface:Detailed 'Wall W' (line 12): zone 'Zone Two' does not exist",
        ),
        ("Relative,Relative,Relative;", "Sideways,Relative,Relative;", "GlobalGeometryRules (line 3): Coordinate System 'Sideways'"),
        (
            "Floor,Floor,C1",
            "Wall s,Floor,C1",
            "BuildingSurface:Detailed 'Wall s' (line 16): surface name 'Wall s' is already used by BuildingSurface:Detailed 'Wall S' (line 6)",
        ),
        (
            "Overhang B,,4,\n  1,-1,2.8, 1,0,2.8, 9,0,2.8, 9,-1,2.8;",
            "Overhang B,,4,\n  1,-1,2.8, 1,-1,2.8, 1,-1,2.8, 1,-1,2.8;",
            "Shading:Building:Detailed 'Overhang B' (line 20): has no area",
        ),
        (
            "Win S,Window,WIN",
            "Win S,Skylight,WIN",
            "FenestrationSurface:Detailed 'Win S' (line 18): Surface Type 'Skylight' is not one of Window, Door,",
        ),
    ];
    for (from, to, expected) in cases {
        assert!(MODEL.contains(from), "{from}");
        let e = read_err(&MODEL.replacen(from, to, 1));
        assert!(e.starts_with("m.idf: ") && e.contains(expected), "{e}\nexpected: {expected}");
    }
    let e = read_err("Version,25.2;\nZone,Z;\nBuildingSurface:Detailed,W,Wall,C,Z;\n");
    assert!(e.contains("BuildingSurface:Detailed 'W' (line 3): has 0 vertices"), "{e}");
    let e = read_err("Version,25.2;\nZone,Z;\nWall:Exterior,W,C,Z,,180,90,0,0,0;\n");
    assert!(e.contains("Wall:Exterior 'W' (line 3): field 10 (Length) is missing"), "{e}");
}

/// Surfaces EnergyPlus keeps dark get no sunlit fraction (its ExtSolar: Outdoors and not NoSun,
/// windows and doors taking both from their base surface), and the warnings say why: a NoSun
/// exterior wall and its window, a door in an underground wall, a window in a ground wall written
/// as a detailed surface, while the sun-exposed wall and its window still receive.
#[test]
fn surfaces_energyplus_keeps_dark_are_not_receivers() {
    let text = "Version,25.2;
GlobalGeometryRules,UpperLeftCorner,Counterclockwise,World;
Zone,Z;
BuildingSurface:Detailed,Lit,Wall,C,Z,,Outdoors,,SunExposed,WindExposed,autocalculate,4, 0,0,3, 0,0,0, 10,0,0, 10,0,3;
FenestrationSurface:Detailed,Lit Win,Window,W,Lit,,autocalculate,,1,4, 2,0,2.5, 2,0,1, 8,0,1, 8,0,2.5;
BuildingSurface:Detailed,Shaded,Wall,C,Z,,Outdoors,,NoSun,WindExposed,autocalculate,4, 10,0,3, 10,0,0, 10,8,0, 10,8,3;
FenestrationSurface:Detailed,Shaded Win,Window,W,Shaded,,autocalculate,,1,4, 10,2,2.5, 10,2,1, 10,6,1, 10,6,2.5;
Wall:Underground,UG,C,Z,,270,90,0,8,0,8,3;
Door,UG Door,D,UG,1,1,0,1,2;
BuildingSurface:Detailed,Ground Wall,Wall,C,Z,,Ground,,NoSun,NoWind,autocalculate,4, 10,8,3, 10,8,0, 0,8,0, 0,8,3;
FenestrationSurface:Detailed,Ground Win,Window,W,Ground Wall,,autocalculate,,1,4, 6,8,2.5, 6,8,1, 2,8,1, 2,8,2.5;
";
    let b = read(text);
    assert_eq!(b.receiver_names(), ["Lit", "Lit Win"]);
    for (name, why) in [
        ("Shaded", "its Sun Exposure is NoSun"),
        ("Shaded Win", "its base surface 'Shaded' has Sun Exposure NoSun"),
        ("UG Door", "its base surface 'UG' has Outside Boundary Condition Ground"),
        ("Ground Win", "its base surface 'Ground Wall' has Outside Boundary Condition Ground"),
    ] {
        let w = b.warnings.iter().find(|w| w.contains(&format!("'{name}'"))).unwrap_or_else(|| panic!("{name}: {:?}", b.warnings));
        assert!(w.contains("gets no sunlit fraction") && w.contains(why), "{w}");
    }
    // The underground wall and the ground wall are simply not exterior: no warning for them.
    assert!(!b.warnings.iter().any(|w| w.contains("'UG' (") || w.contains("'Ground Wall' (")), "{:?}", b.warnings);
    // In the scene they still cast shadows, but only the two sun-exposed surfaces receive.
    let mut builder = SceneBuilder::new();
    b.add_to(&mut builder).unwrap();
    let scene = builder.build().unwrap();
    let names: Vec<&str> = scene.receivers.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["Lit", "Lit Win"]);
}

/// A window set back behind its wall is shaded by EnergyPlus's reveal rule as the window is only
/// when listed from its upper-left corner as an upright rectangle: listed from another corner, the
/// warning says EnergyPlus's own fraction for it is not the window's. Flush windows and windows
/// listed from the upper-left get no warning.
#[test]
fn set_back_windows_listed_from_another_corner_warn() {
    let window = "  2,0,2.5, 2,0,1, 8,0,1, 8,0,2.5;";
    assert!(MODEL.contains(window));
    let warned = |text: String| read(&text).warnings.into_iter().find(|w| w.contains("Win S"));
    assert_eq!(warned(MODEL.to_string()), None, "flush");
    assert_eq!(warned(MODEL.replace(window, "  2,0.15,2.5, 2,0.15,1, 8,0.15,1, 8,0.15,2.5;")), None, "set back, from the upper-left");
    assert_eq!(warned(MODEL.replace(window, "  2,0,1, 8,0,1, 8,0,2.5, 2,0,2.5;")), None, "flush, from the lower-left");
    let warning = warned(MODEL.replace(window, "  2,0.15,1, 8,0.15,1, 8,0.15,2.5, 2,0.15,2.5;")).expect("set back, from the lower-left");
    assert!(warning.starts_with("FenestrationSurface:Detailed 'Win S' (line 18) is set back 0.150 m behind 'Wall S'"), "{warning}");
    assert!(warning.contains("SHDRVL"), "{warning}");
}
