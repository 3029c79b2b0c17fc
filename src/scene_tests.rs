//! The scene builder's tests: instancing, planar parts, mirrors, leaves, veils, bad input.

use super::*;

fn quad(z: f32) -> SourceMesh {
    SourceMesh { positions: vec![[0., 0., z], [1., 0., z], [1., 1., z], [0., 1., z]], indices: vec![0, 1, 2, 0, 2, 3] }
}

fn node(name: &str, mesh: usize, receiver: bool, t: DMat4) -> SourceNode {
    SourceNode { name: name.into(), origin: format!("test.glb: node '{name}'"), mesh, transform: t, receiver }
}

#[test]
fn shared_mesh_is_instanced_not_copied() {
    let mut b = SceneBuilder::new();
    let m = b.add_mesh("quad", quad(0.0));
    for i in 0..3 {
        b.add_node(node(&format!("q{i}"), m, i == 1, DMat4::from_translation(DVec3::new(i as f64 * 2.0, 0.0, 0.0))));
    }
    let s = b.build().unwrap();
    assert_eq!(s.meshes.len(), 2, "static mesh + one shared mesh");
    assert_eq!(s.instances.len(), 4);
    assert_eq!(s.receivers.len(), 1);
    assert_eq!(s.receivers[0].name, "q1");
    assert!((s.receivers[0].area - 1.0).abs() < 1e-9);
    assert_eq!(s.triangle_count(), 6);
    let ids: Vec<_> = s.world_triangles().map(|(_, id)| id).collect();
    assert_eq!(ids.iter().filter(|i| i.is_some()).count(), 2);
}

#[test]
fn non_planar_receiver_is_split_into_named_parts() {
    let mut b = SceneBuilder::new();
    // Two faces of a box corner: z = 0 plane and x = 0 plane.
    let m = b.add_mesh(
        "corner",
        SourceMesh {
            positions: vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 0., 1.], [0., 1., 1.], [0., 1., 0.]],
            indices: vec![0, 1, 2, 0, 4, 3, 0, 5, 4],
        },
    );
    b.add_node(node("Box", m, true, DMat4::IDENTITY));
    let s = b.build().unwrap();
    let names: Vec<_> = s.receivers.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["Box#1", "Box#2"]);
    assert!((s.receivers[1].area - 1.0).abs() < 1e-9);
}

#[test]
fn a_sliver_belongs_to_the_plane_its_vertices_lie_on() {
    let mut b = SceneBuilder::new();
    // A 3 m × 1 m wall in z = 0 and a sliver 2 µm wide along its bottom edge whose middle
    // vertex is 1 µm off the plane: its own normal is far from the wall's (rounding decides
    // it), but it is thinner than the coplanar distance, so it is part of the wall.
    let m = b.add_mesh(
        "wall",
        SourceMesh {
            positions: vec![[0., 0., 0.], [3., 0., 0.], [3., 1., 0.], [0., 1., 0.], [1.5, -2e-6, 1e-6]],
            indices: vec![0, 1, 2, 0, 2, 3, 0, 4, 1],
        },
    );
    b.add_node(node("Wall", m, true, DMat4::IDENTITY));
    let s = b.build().unwrap();
    let names: Vec<_> = s.receivers.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["Wall"]);
    // A genuine second face (a 1 m² triangle at right angles) still splits.
    let mut b = SceneBuilder::new();
    let m = b.add_mesh(
        "corner",
        SourceMesh { positions: vec![[0., 0., 0.], [3., 0., 0.], [3., 1., 0.], [0., 0., 1.]], indices: vec![0, 1, 2, 0, 3, 1] },
    );
    b.add_node(node("Corner", m, true, DMat4::IDENTITY));
    assert_eq!(b.build().unwrap().receivers.len(), 2);
}

#[test]
fn a_mirror_shares_geometry_and_faces_the_other_way() {
    let mut b = SceneBuilder::new();
    b.add_object("test", "LOUVER", quad(1.0), true);
    b.add_mirror("LOUVER", "Mir-LOUVER");
    let s = b.build().unwrap();
    assert_eq!(s.receivers.len(), 2);
    assert_eq!(s.receivers[1].gpu_id, 0);
    assert_eq!(s.receivers[1].normal, -s.receivers[0].normal);
    assert_eq!(s.triangle_count(), 2, "drawn once");
}

#[test]
fn leaves_are_connected_groups_and_each_placement_has_its_own() {
    let mut b = SceneBuilder::new();
    // Two separate quads: two leaves.
    let mut two = quad(0.0);
    two.positions.extend(quad(1.0).positions);
    two.indices.extend([4, 5, 6, 4, 6, 7]);
    let m = b.add_mesh("two leaves", two);
    let foliage = NodeVeil { foliage: true, transmittance: 0.0 };
    for i in 0..2 {
        b.set_node_veil(b.node_count(), foliage);
        b.add_node(node(&format!("tree{i}"), m, false, DMat4::from_translation(DVec3::new(5.0 * i as f64, 0.0, 0.0))));
    }
    // The same mesh placed opaque gets its own copy (veils live in the vertices).
    b.add_node(node("statue", m, false, DMat4::IDENTITY));
    b.add_object("test", "floor", quad(-1.0), true);
    let s = b.build().unwrap();
    assert_eq!(s.meshes.len(), 3, "static + foliage copy + opaque copy");
    assert_eq!(s.veil_counts(), (4, 0));
    let ranks: Vec<f32> = s.veiled_triangles().filter(|(_, _, v)| v.rank >= 0.0).map(|(_, _, v)| v.rank).collect();
    assert_eq!(ranks.len(), 8);
    assert!(ranks.iter().all(|r| (0.0..1.0).contains(r)));
    let leaf = |k: usize| ranks[2 * k];
    assert_eq!(ranks[0], ranks[1], "a quad's two triangles are one leaf");
    assert!(leaf(0) != leaf(1) && leaf(0) != leaf(2) && leaf(1) != leaf(3), "{ranks:?}");
    assert!(s.veiled_triangles().all(|(_, _, v)| v.present(0.0, 1.0)));
    assert_eq!(s.veiled_triangles().filter(|(_, _, v)| !v.present(0.0, 0.0)).count(), 8, "no leaves at 0");
}

#[test]
fn see_through_receivers_and_bad_transmittance_are_refused() {
    let mut b = SceneBuilder::new();
    b.set_node_veil(0, NodeVeil { foliage: false, transmittance: 0.5 });
    b.add_object("test.glb", "Screen", quad(0.0), true);
    let e = b.build().unwrap_err().to_string();
    assert!(e.contains("node 'Screen'") && e.contains("must be opaque"), "{e}");
    let mut b = SceneBuilder::new();
    b.set_node_veil(0, NodeVeil { foliage: false, transmittance: 1.0 });
    b.add_object("test.glb", "Screen", quad(0.0), false);
    let e = b.build().unwrap_err().to_string();
    assert!(e.contains("node 'Screen'") && e.contains("outside [0, 1)"), "{e}");
}

#[test]
fn bad_inputs_are_named() {
    let mut b = SceneBuilder::new();
    let mut q = quad(0.0);
    q.positions[2][1] = f32::NAN;
    let m = b.add_mesh("quad", q);
    b.add_node(node("Bad", m, false, DMat4::IDENTITY));
    let e = b.build().unwrap_err().to_string();
    assert!(e.contains("test.glb") && e.contains("node 'Bad'") && e.contains("non-finite"), "{e}");

    let mut b = SceneBuilder::new();
    let m = b.add_mesh("line", SourceMesh { positions: vec![[0., 0., 0.], [1., 0., 0.], [2., 0., 0.]], indices: vec![0, 1, 2] });
    b.add_node(node("Flat", m, true, DMat4::IDENTITY));
    let e = b.build().unwrap_err().to_string();
    assert!(e.contains("node 'Flat'") && e.contains("zero area"), "{e}");

    let mut b = SceneBuilder::new();
    let m1 = b.add_mesh("a", quad(0.0));
    let m2 = b.add_mesh("b", quad(1.0));
    b.add_node(node("Same", m1, true, DMat4::IDENTITY));
    b.add_node(node("Same", m2, true, DMat4::IDENTITY));
    let e = b.build().unwrap_err().to_string();
    assert!(e.contains("duplicate receiver name 'Same'"), "{e}");
}
