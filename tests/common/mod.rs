//! Scene-building helpers shared by the integration tests.
#![allow(dead_code)]

pub mod energyplus;

use std::path::PathBuf;

use glam::DVec3;
use sunlit::count::ViewRequest;
use sunlit::count::gpu::{Counted, Counter, CounterOptions};
use sunlit::scene::{Scene, SceneBuilder, SourceMesh};

/// Builds scenes from named polygons (fans of triangles) and boxes.
#[derive(Default)]
pub struct TestScene {
    builder: SceneBuilder,
}

impl TestScene {
    pub fn new() -> Self {
        Self::default()
    }

    /// A planar polygon (convex, counter-clockwise seen from its outward side), as a triangle fan.
    pub fn polygon(&mut self, name: &str, corners: &[DVec3], receiver: bool) -> &mut Self {
        let positions = corners.iter().map(|p| [p.x as f32, p.y as f32, p.z as f32]).collect();
        let indices = (1..corners.len() as u32 - 1).flat_map(|i| [0, i, i + 1]).collect();
        self.mesh(name, SourceMesh { positions, indices }, receiver)
    }

    /// Any triangle mesh as one node.
    pub fn mesh(&mut self, name: &str, mesh: SourceMesh, receiver: bool) -> &mut Self {
        self.builder.add_object("test", name, mesh, receiver);
        self
    }

    /// An axis-aligned closed box (shadow caster only).
    pub fn cuboid(&mut self, name: &str, lo: DVec3, hi: DVec3) -> &mut Self {
        let c = |i: usize| {
            DVec3::new(if i & 1 == 0 { lo.x } else { hi.x }, if i & 2 == 0 { lo.y } else { hi.y }, if i & 4 == 0 { lo.z } else { hi.z })
        };
        let positions = (0..8)
            .map(|i| {
                let p = c(i);
                [p.x as f32, p.y as f32, p.z as f32]
            })
            .collect();
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let indices = quads.iter().flat_map(|q: &[u32; 4]| [q[0], q[1], q[2], q[0], q[2], q[3]]).collect();
        self.mesh(name, SourceMesh { positions, indices }, false)
    }

    pub fn build(self) -> Scene {
        self.builder.build().expect("test scene builds")
    }
}

/// A vertical rectangle facing −y (south) at y = `y`, x in [x0, x1], z in [z0, z1].
pub fn south_rect(x0: f64, x1: f64, z0: f64, z1: f64, y: f64) -> Vec<DVec3> {
    vec![DVec3::new(x0, y, z0), DVec3::new(x1, y, z0), DVec3::new(x1, y, z1), DVec3::new(x0, y, z1)]
}

/// A horizontal rectangle facing up at height z.
pub fn flat_rect(x0: f64, x1: f64, y0: f64, y1: f64, z: f64) -> Vec<DVec3> {
    vec![DVec3::new(x0, y0, z), DVec3::new(x1, y0, z), DVec3::new(x1, y1, z), DVec3::new(x0, y1, z)]
}

pub fn sun(azimuth: f64, altitude: f64) -> DVec3 {
    sunlit::sun::SunPosition::new(azimuth, altitude).expect("valid sun").direction()
}

pub fn counter(resolution: u32) -> Counter {
    pollster::block_on(Counter::new(CounterOptions { resolution, ..Default::default() }))
        .expect("a GPU adapter (lavapipe: apt-get install mesa-vulkan-drivers) — GPU tests never skip")
}

/// A counter that counts each view at 64² first and finer, up to `resolution`, where its
/// estimated error exceeds `accuracy`.
pub fn adaptive_counter(resolution: u32, accuracy: f64) -> Counter {
    pollster::block_on(Counter::new(CounterOptions { resolution, accuracy: Some(accuracy), ..Default::default() }))
        .expect("a GPU adapter (lavapipe: apt-get install mesa-vulkan-drivers) — GPU tests never skip")
}

/// GPU fractions for every receiver of `scene` under each sun.
pub fn gpu_fractions(counter: &Counter, scene: &Scene, requests: &[ViewRequest]) -> Vec<Counted> {
    let gpu = counter.upload(scene).expect("upload");
    pollster::block_on(counter.fractions(&gpu, requests)).expect("count")
}

pub fn receiver_id(scene: &Scene, name: &str) -> u32 {
    scene.receiver(name).unwrap_or_else(|| panic!("receiver {name}")).0
}

/// A closed cube of side `side` from the origin (12 triangles), for instancing.
pub fn cube_mesh(side: f32) -> SourceMesh {
    let positions = (0..8).map(|i| [side * (i & 1) as f32, side * ((i >> 1) & 1) as f32, side * ((i >> 2) & 1) as f32]).collect();
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let indices = quads.iter().flat_map(|q: &[u32; 4]| [q[0], q[1], q[2], q[0], q[2], q[3]]).collect();
    SourceMesh { positions, indices }
}

/// A private XDG_RUNTIME_DIR for the CLI under test, so Mesa does not warn on stderr.
pub fn runtime_dir() -> PathBuf {
    let dir = std::env::temp_dir().join("sunlit-test-runtime");
    std::fs::create_dir_all(&dir).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700)).unwrap();
    dir
}
