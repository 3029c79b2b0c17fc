//! BRE 209 (3rd ed., 2022), 2.2: the vertical sky component (VSC) at a window's reference point,
//! the illuminance the visible sky gives the point's plane under the CIE standard overcast sky
//! ([`LuminanceSky::CieOvercast`]) as a % of what the whole unobstructed sky gives a horizontal
//! plane (7π Lz/9). Direct sun and the ground are not part of it; an unobstructed vertical point
//! has 39.6 %.
//!
//! Each of Tregenza's 145 patches is cut into [`SUBDIVISION`]² sub-patches ([`Patch::split`],
//! about 2° a side); a point's VSC is Σ visibility · ∫ max(0, n·d) dΩ · L/Lz over the
//! sub-patches, ∫ cos dΩ in closed form over each sub-patch ([`Patch::weight`]) and the luminance
//! at its cos-weighted direction (L is linear in sin γ, so a 2° row's mean is its middle's to
//! 1e-4). Visibility is asked along each sub-patch's centre, by the exact shadow rays, for every
//! point ([`Windows`]); a sub-patch whose centre is behind the point's receiver
//! is skipped (it lies within 1° of the plane, where cos < 0.02: under 0.05 % of the VSC).

use std::collections::HashMap;

use glam::DVec3;

use super::{Ask, Windows};
use crate::sky::luminance::LuminanceSky;
use crate::sky::patches::{Patch, SkyPatches};

/// Rows and columns each Tregenza patch is cut into.
pub const SUBDIVISION: usize = 6;

/// Each point's vertical sky component, and what it would be with nothing in the way.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VscValues {
    /// VSC per point, % (points in their input order).
    pub vsc: Vec<f64>,
    /// The same with no obstruction (39.6 % for a vertical point), %.
    pub unobstructed: Vec<f64>,
}

/// Per distinct normal, each sub-patch's share of the unobstructed horizontal illuminance (%).
struct Shares {
    index: HashMap<[u64; 3], usize>,
    tables: Vec<Vec<f64>>,
}

impl Shares {
    fn of(&mut self, normal: DVec3, fine: &[Patch], sky: LuminanceSky) -> usize {
        *self.index.entry(normal.to_array().map(f64::to_bits)).or_insert_with(|| {
            let scale = 100.0 / sky.horizontal_illuminance();
            self.tables.push(
                fine.iter()
                    .map(|p| {
                        let w = p.weight(normal);
                        w.weight * sky.relative_luminance(w.direction.z) * scale
                    })
                    .collect(),
            );
            self.tables.len() - 1
        })
    }
}

/// The sub-patches a point's sky is asked along (Tregenza's, [`SUBDIVISION`]² each).
pub fn sub_patches() -> Vec<Patch> {
    SkyPatches::tregenza().patches.iter().flat_map(|p| p.split(SUBDIVISION)).collect()
}

/// Every point's VSC (bare trees: BRE's overcast sky is a winter sky, and leaves only add
/// obstruction in summer). `progress(done, total)` counts sub-patches.
pub fn vsc(windows: &Windows, progress: &mut dyn FnMut(usize, usize)) -> VscValues {
    let sky = LuminanceSky::CieOvercast;
    let fine = sub_patches();
    let mut shares = Shares { index: HashMap::new(), tables: Vec::new() };
    let class: Vec<usize> = (0..windows.len()).map(|i| shares.of(windows.normal(i), &fine, sky)).collect();
    let asks: Vec<Ask> = fine.iter().map(|p| Ask { direction: p.direction, leaves: 0.0 }).collect();
    let n = windows.len();
    let parts = windows.sweep(&asks, progress, || vec![0.0f64; n], |acc, k, i, v| acc[i] += shares.tables[class[i]][k] * f64::from(v));
    let mut values = vec![0.0; n];
    for part in parts {
        crate::map::add_into(&mut values, &part);
    }
    // The unobstructed sum over the same sub-patches the rays ask (centre in front of the plane).
    let unobstructed = (0..n)
        .map(|i| {
            let normal = windows.normal(i);
            fine.iter()
                .zip(&shares.tables[class[i]])
                .filter(|(p, _)| normal.dot(p.direction) > crate::count::MIN_COS_INCIDENCE)
                .map(|(_, s)| s)
                .sum()
        })
        .collect();
    VscValues { vsc: values, unobstructed }
}
