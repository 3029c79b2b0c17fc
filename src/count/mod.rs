//! The counting stage: sunlit fractions of receivers for sun directions.
//!
//! Owns the shared vocabulary ([`ViewRequest`], [`cos_incidence`], the facing-away rule) and its
//! two implementations: the GPU pixel counter ([`gpu`], native and web) and the exact CPU
//! polygon-clipping reference ([`exact`]) that tests hold the GPU to.

pub mod cull;
pub mod exact;
pub mod gpu;
pub mod group;
pub mod hybrid;
pub mod lanes;
pub mod view;

use glam::DVec3;

/// Below this cosine of incidence a surface counts as facing away from the sun (EnergyPlus's rule).
pub const MIN_COS_INCIDENCE: f64 = 1e-5;

/// One (receiver, sun) pair to evaluate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewRequest {
    /// Receiver id (index into `Scene::receivers`).
    pub receiver: u32,
    /// Unit vector towards the sun, world axes.
    pub sun: DVec3,
}

/// Cosine of the angle between a surface normal and the direction to the sun.
pub fn cos_incidence(normal: DVec3, sun: DVec3) -> f64 {
    normal.dot(sun)
}

/// Whether a view needs no rendering: the sun is down (cos zenith below EnergyPlus's 1e-5
/// "sun is up" threshold) or behind the surface (fraction 0).
pub fn is_dark(normal: DVec3, sun: DVec3) -> bool {
    sun.z < MIN_COS_INCIDENCE || cos_incidence(normal, sun) <= MIN_COS_INCIDENCE
}
