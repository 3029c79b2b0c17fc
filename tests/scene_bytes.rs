//! The scene's binary encoding (`Scene::to_bytes`, `Scene::from_bytes`), as the page's clipping
//! workers get their scene: a decoded scene gives the exact engine's fractions bit for bit, with
//! instancing, foliage and see-through casters; truncated, corrupt, foreign and inconsistent
//! bytes are refused with their reason, never a panic or an allocation of a corrupt length.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

use sunlit::count::ViewRequest;
use sunlit::count::exact::engine::ExactEngine;
use sunlit::error::{Error, SceneBytesError};
use sunlit::model::{LoadOptions, load_bytes};
use sunlit::scene::Scene;
use sunlit::scene::codec::{MAGIC, VERSION};

/// Five trees before a three-storey facade, read from a glb: one trunk mesh placed five times
/// (the four opaque ones instanced), foliage crowns, and the first trunk see-through.
fn street() -> Scene {
    let glb = sunlit::bench::street_trees_glb(400, 11);
    let options = LoadOptions { transmittance: vec![("TRUNK_1".into(), 0.4)], ..Default::default() };
    load_bytes(&[("street.glb".into(), glb)], &options).unwrap()
}

fn requests(scene: &Scene) -> Vec<ViewRequest> {
    let suns = sunlit::bench::suns(40, 5);
    let mut out = Vec::new();
    for receiver in 0..scene.receivers.len() as u32 {
        for &sun in &suns {
            for leaves in [0.0, 0.37, 0.8, 1.0] {
                out.push(ViewRequest::new(receiver, sun).with_leaves(leaves));
            }
        }
    }
    out
}

fn refused(bytes: &[u8]) -> SceneBytesError {
    match Scene::from_bytes(bytes) {
        Err(Error::SceneBytes(why)) => why,
        Err(other) => panic!("refused as {other}, not as scene bytes"),
        Ok(_) => panic!("{} bytes decoded", bytes.len()),
    }
}

#[test]
fn a_decoded_scene_gives_the_same_fractions_bit_for_bit() {
    let scene = street();
    let mut uses = vec![0; scene.meshes.len()];
    scene.instances.iter().for_each(|i| uses[i.mesh] += 1);
    assert!(uses.iter().any(|&n| n >= 4), "the opaque trunks share one mesh: {uses:?}");
    assert!(scene.has_foliage() && scene.leaves == 400, "leaves: {}", scene.leaves);
    assert!(scene.see_through_triangles > 0, "the first trunk is see-through");

    let bytes = scene.to_bytes();
    assert_eq!(bytes[..8], MAGIC);
    let decoded = Scene::from_bytes(&bytes).unwrap();
    assert_eq!(decoded.to_bytes(), bytes, "the encoding is stable: decode then encode gives the same bytes");
    assert_eq!(decoded.receivers.iter().map(|r| &r.name).collect::<Vec<_>>(), scene.receivers.iter().map(|r| &r.name).collect::<Vec<_>>());
    assert_eq!((decoded.leaves, decoded.see_through_triangles), (scene.leaves, scene.see_through_triangles));

    let requests = requests(&scene);
    let original = ExactEngine::new(&scene).fractions(&requests);
    let again = ExactEngine::new(&decoded).fractions(&requests);
    let bits = |f: &[f64]| f.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&again), bits(&original));
    // The views are not trivial: leaves and trunks shade some of them, partly.
    let partial = original.iter().filter(|&&f| f > 0.01 && f < 0.99).count();
    assert!(partial > 20, "{partial} partly shaded views of {}", original.len());
    let by_leaves: Vec<f64> = original.chunks(4).map(|c| c[0] - c[3]).collect();
    assert!(by_leaves.iter().any(|&d| d > 0.01), "full leaves shade more than none somewhere");
}

/// Encoded, decoded and encoded again: the same bytes, and the same exact fractions.
fn round_trips(scene: &Scene, what: &str) {
    let bytes = scene.to_bytes();
    let decoded = Scene::from_bytes(&bytes).unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(decoded.to_bytes(), bytes, "{what}");
    let requests: Vec<ViewRequest> = (0..scene.receivers.len() as u32)
        .flat_map(|r| sunlit::bench::suns(12, 3).into_iter().map(move |sun| ViewRequest::new(r, sun)))
        .collect();
    let bits = |f: Vec<f64>| f.into_iter().map(f64::to_bits).collect::<Vec<_>>();
    assert_eq!(bits(ExactEngine::new(&decoded).fractions(&requests)), bits(ExactEngine::new(scene).fractions(&requests)), "{what}");
}

#[test]
fn every_way_into_a_scene_round_trips() {
    use sunlit::model::arrays::{Arrays, scene_from_arrays};
    use sunlit::model::office_idf::{Shading, office_idf};
    use sunlit::model::placed::{Placed, scene_from_placed};
    let glb = sunlit::model::office::office(3).to_glb();
    round_trips(&load_bytes(&[("office.glb".into(), glb)], &LoadOptions::default()).unwrap(), "office.glb");
    let idf = office_idf(2, true, Shading::None).into_bytes();
    round_trips(&load_bytes(&[("office.idf".into(), idf)], &LoadOptions::default()).unwrap(), "office.idf");
    // A wall (receiver) and a slat before it, as the JS API's typed arrays.
    let positions =
        [0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 4.0, 0.0, 3.0, 0.0, 0.0, 3.0, 0.0, -1.0, 2.0, 4.0, -1.0, 2.0, 4.0, -0.5, 2.2, 0.0, -0.5, 2.2];
    let indices = [0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7];
    let names = ["Wall".to_string()];
    let arrays = Arrays { positions: &positions, indices: &indices, triangle_receivers: &[0, 0, -1, -1], names: &names, y_up: false };
    round_trips(&scene_from_arrays(&arrays).unwrap(), "arrays");
    // The same slat placed twice (one mesh, two placements) before the wall, as three.js meshes.
    let mut matrices = Vec::new();
    for z in [0.0, 0.6, 0.0] {
        matrices.extend([1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, z, 1.0]);
    }
    let names = ["Slat1".to_string(), "Slat2".to_string(), "Wall".to_string()];
    let placed = Placed {
        positions: &positions,
        vertex_starts: &[0, 4, 8],
        indices: &[0, 1, 2, 0, 2, 3, 0, 1, 2, 0, 2, 3],
        index_starts: &[0, 6, 12],
        placement_meshes: &[1, 1, 0],
        matrices: &matrices,
        names: &names,
        receivers: &[0, 0, 1],
        y_up: false,
    };
    let scene = scene_from_placed(&placed).unwrap();
    assert!(scene.instances.iter().filter(|i| i.mesh == scene.instances[1].mesh).count() >= 2, "the slat is instanced");
    round_trips(&scene, "placed meshes");
}

#[test]
fn truncated_foreign_and_corrupt_bytes_are_refused_by_their_reason() {
    let bytes = street().to_bytes();
    // Every prefix is refused (a sample of them: the whole scan is quadratic).
    for cut in (0..bytes.len()).step_by(97).chain([1, 8, 11, 12, bytes.len() - 1]) {
        match refused(&bytes[..cut]) {
            SceneBytesError::Truncated { offset, need, left, .. } => assert!(need > left && offset <= cut, "cut at {cut}"),
            SceneBytesError::NotAScene => assert!(cut < 8, "cut at {cut}"),
            other => panic!("cut at {cut}: {other}"),
        }
    }
    let mut extra = bytes.clone();
    extra.extend_from_slice(&[0, 0, 0]);
    assert_eq!(refused(&extra), SceneBytesError::TrailingBytes { extra: 3 });

    let mut foreign = bytes.clone();
    foreign[0] = b'X';
    assert_eq!(refused(&foreign), SceneBytesError::NotAScene);
    let mut later = bytes.clone();
    later[8..12].copy_from_slice(&(VERSION + 1).to_le_bytes());
    assert_eq!(refused(&later), SceneBytesError::Version { found: VERSION + 1, supported: VERSION });
    let message = Error::SceneBytes(refused(&later)).to_string();
    assert!(message.contains(&format!("version {}", VERSION + 1)), "{message}");

    // A corrupt list length (the meshes', right after the header) is refused before allocating.
    let mut huge = bytes.clone();
    huge[12..20].copy_from_slice(&u64::MAX.to_le_bytes());
    assert!(matches!(refused(&huge), SceneBytesError::Truncated { reading: "meshes", .. }));
}

#[test]
fn an_index_past_its_list_or_a_non_finite_vertex_is_refused() {
    let scene = street();
    let mut bad = scene.clone();
    bad.instances[1].mesh = 99;
    let SceneBytesError::Invalid { what, reason } = refused(&bad.to_bytes()) else { panic!("accepted a mesh past the list") };
    assert_eq!((what.as_str(), reason.as_str()), ("instance 1", format!("mesh 99 of {}", scene.meshes.len()).as_str()));

    let mut bad = scene.clone();
    let last = bad.meshes[0].positions.len() as u32;
    bad.meshes[0].indices[2] = last;
    assert!(matches!(refused(&bad.to_bytes()), SceneBytesError::Invalid { reason, .. } if reason.contains("past its")));

    let mut bad = scene.clone();
    bad.meshes[0].positions[0][1] = f32::NAN;
    assert!(matches!(refused(&bad.to_bytes()), SceneBytesError::Invalid { reason, .. } if reason.contains("not finite")));

    let mut bad = scene.clone();
    bad.receivers[0].gpu_id = 1000;
    assert!(matches!(refused(&bad.to_bytes()), SceneBytesError::Invalid { what, .. } if what.starts_with("receiver 0")));

    let mut bad = scene;
    bad.meshes[0].surfaces.pop();
    assert!(matches!(refused(&bad.to_bytes()), SceneBytesError::Invalid { reason, .. } if reason.contains("surface values")));
}
