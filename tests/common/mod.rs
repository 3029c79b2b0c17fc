//! Scene-building helpers shared by the integration tests.
#![allow(dead_code)]

pub mod energyplus;
pub mod inside;
pub mod overflow;

use std::path::{Path, PathBuf};

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

/// Perez 1990 coefficients, typed in again from the paper for an independent check.
pub const LIMITS: [f64; 7] = [1.065, 1.230, 1.500, 1.950, 2.800, 4.500, 6.200];
pub const PEREZ: [[f64; 6]; 8] = [
    [-0.008, 0.588, -0.062, -0.060, 0.072, -0.022],
    [0.130, 0.683, -0.151, -0.019, 0.066, -0.029],
    [0.330, 0.487, -0.221, 0.055, -0.064, -0.026],
    [0.568, 0.187, -0.295, 0.109, -0.152, -0.014],
    [0.873, -0.392, -0.362, 0.226, -0.462, 0.001],
    [1.132, -1.237, -0.412, 0.288, -0.823, 0.056],
    [1.060, -1.600, -0.359, 0.264, -1.127, 0.131],
    [0.678, -0.327, -0.250, 0.156, -1.377, 0.251],
];

/// The closed-form Perez sky diffuse (W/m²) on an unobstructed surface with normal `n`.
/// `elevation` in metres thins the air mass as EnergyPlus does (× (1 − 0.1·elevation/1000)).
pub fn closed_form_perez(n: DVec3, sun: DVec3, dni: f64, dhi: f64, elevation: f64) -> f64 {
    let z = sun.z.acos();
    let m = 1.0 - 0.1 * elevation / 1000.0;
    let air_mass = if z.to_degrees() <= 75.0 { m / sun.z } else { m / (sun.z + 0.15 * (93.9 - z.to_degrees()).powf(-1.253)) };
    let k = 1.041 * z.powi(3);
    let epsilon = ((dni + dhi) / dhi + k) / (1.0 + k);
    let delta = dhi * air_mass / 1353.0;
    let c = PEREZ[LIMITS.iter().take_while(|&&l| epsilon >= l).count()];
    let f1 = (c[0] + c[1] * delta + c[2] * z).max(0.0);
    let f2 = c[3] + c[4] * delta + c[5] * z;
    let (a, b) = (n.dot(sun).max(0.0), sun.z.max(85f64.to_radians().cos()));
    let sin_tilt = (1.0 - n.z * n.z).max(0.0).sqrt();
    // EnergyPlus keeps a near-horizontal roof's circumsolar ratio at 1 with the sun below 5°.
    let circumsolar = if sun.z < 85f64.to_radians().cos() && sin_tilt < 0.1 { 1.0 } else { a / b };
    dhi * ((1.0 - f1) * (1.0 + n.z) / 2.0 + f1 * circumsolar + f2 * sin_tilt).max(0.0)
}

/// The Python with pyradiance: `SUNLIT_RADIANCE_PYTHON`, else .venv-rad's. Panics saying how to
/// get it.
pub fn radiance_python() -> PathBuf {
    if let Some(p) = std::env::var_os("SUNLIT_RADIANCE_PYTHON") {
        return PathBuf::from(p);
    }
    let venv = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv-rad/bin/python");
    assert!(
        venv.exists(),
        "Radiance (pyradiance) not found: run `SUNLIT_RADIANCE=1 . scripts/setup.sh` (npm test does) or set SUNLIT_RADIANCE_PYTHON"
    );
    venv
}

/// A scratch folder that is removed when the test that made it passes and kept (for a look at the
/// runs) when it fails: dropped while the thread panics, it stays.
pub struct Scratch(PathBuf);

impl Scratch {
    /// `sunlit-PREFIX-NAME-PID` in the temporary folder, emptied first.
    pub fn new(prefix: &str, name: &str) -> Self {
        Self::named(&format!("{prefix}-{name}"))
    }

    /// `sunlit-NAME-PID` in the temporary folder, emptied first.
    pub fn named(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("sunlit-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }
}

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("kept for a look: {}", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}
