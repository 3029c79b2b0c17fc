//! The counting stage: sunlit fractions of receivers for sun directions.
//!
//! Owns the shared vocabulary: one request ([`ViewRequest`]: receiver, sun, leaf fraction), one
//! answer ([`ViewAnswer`]), the [`Engine`] trait that turns the first into the second,
//! [`cos_incidence`] and the facing-away rule. Two engines implement it: the GPU pixel counter
//! ([`gpu`], native and web; [`lanes`] shares views over several devices) and the exact CPU
//! polygon-clipping reference ([`exact`]) that tests hold the GPU to. A caller can hand any view
//! to either. [`rays`] answers single points by shadow rays, for studies that ask few points
//! about many directions.

pub mod certify;
pub mod cull;
pub mod exact;
pub mod gpu;
pub mod group;
pub mod hybrid;
pub mod lanes;
pub mod rays;
pub mod view;

use std::future::Future;

use glam::DVec3;

use crate::error::{Error, Result};

/// Below this cosine of incidence a surface counts as facing away from the sun (EnergyPlus's rule).
pub const MIN_COS_INCIDENCE: f64 = 1e-5;

/// One view to evaluate: a receiver, a sun direction and the foliage's leaf fraction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewRequest {
    /// Receiver id (index into `Scene::receivers`).
    pub receiver: u32,
    /// Unit vector towards the sun, world axes.
    pub sun: DVec3,
    /// Leaf fraction of the foliage, 0 (bare) to 1 (full leaf): the leaves whose rank is below
    /// it cast shadows. An f32 because the GPU compares ranks in f32; both engines make the same
    /// test, so they see the same leaves.
    pub leaves: f32,
}

impl ViewRequest {
    /// A view with every leaf on.
    pub fn new(receiver: u32, sun: DVec3) -> Self {
        Self { receiver, sun, leaves: 1.0 }
    }

    /// The same view at leaf fraction `leaves`.
    pub fn with_leaves(self, leaves: f32) -> Self {
        Self { leaves, ..self }
    }
}

/// What an engine answers for one view. The fraction and cosine come from every engine; the
/// pixel facts only from the GPU, and only for a view it rendered.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ViewAnswer {
    /// Sunlit fraction in [0, 1].
    pub fraction: f64,
    /// Cosine of incidence (normal · sun).
    pub cos_incidence: f64,
    /// Pixels the receiver covered in its tile; `None` when no pixels were counted (the exact
    /// reference, or a view decided without a render: sun down, facing away, nothing in front).
    pub covered: Option<u32>,
    /// Side of the tile the view was last counted at; `None` as for `covered`.
    pub side: Option<u32>,
    /// Estimated |error| of `fraction`: 0 from the exact reference and for views decided without
    /// a render; for a counted view the shadow-edge estimate ([`gpu::error_estimate`]) when the
    /// counter counted edges (it had an accuracy target), else `None`.
    pub error_estimate: Option<f64>,
}

/// What kind of views a caller asks for next. Their loads cost the engines differently (a sun
/// view's prism is short and steep; a low sky patch's runs through the whole scene, past many
/// triangles that cost the exact engine little), so `auto` prices each kind on views of its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ViewKind {
    /// Sun positions: the year's views.
    #[default]
    Sun,
    /// Sky directions: sky patches and EnergyPlus's 144 diffuse directions.
    Sky,
}

/// Something that answers views: the GPU counter, the exact reference, or a mix of them.
///
/// Asynchronous because the GPU's read-back is awaited (the web cannot block); the exact
/// reference answers at once.
pub trait Engine {
    /// Views worth handing over at once: callers that report progress or can be cancelled
    /// between calls chunk their requests by a multiple of it.
    fn batch(&self) -> usize;

    /// One answer per request, in request order.
    fn answer(&self, requests: &[ViewRequest]) -> impl Future<Output = Result<Vec<ViewAnswer>>>;

    /// Told that about `views` views will be asked for in all, batch by batch: an engine with a
    /// once-a-run cost (a GPU's start-up) weighs it against the run, not one batch.
    fn expect(&self, _views: usize) {}

    /// Told which kind of views follow, until told otherwise ([`ViewKind::Sun`] at first): an
    /// engine that prices views by a measured profile keeps one per kind.
    fn views_of(&self, _kind: ViewKind) {}

    /// The exact engine's index of the scene, where this engine holds one: the certificates
    /// ([`certify::Certifier::sharing`]) use it instead of building a second.
    fn index(&self) -> Option<&exact::engine::ExactEngine> {
        None
    }
}

/// A leaf fraction as a [`ViewRequest`] takes it, refused outside 0 (bare) ..= 1 (full leaf).
pub fn leaf_fraction(leaves: f64) -> Result<f32> {
    if !(0.0..=1.0).contains(&leaves) {
        return Err(Error::argument("leaves", format!("{leaves} is outside 0..=1")));
    }
    Ok(leaves as f32)
}

/// Refuses a request for a receiver the scene does not have (both engines do, alike).
pub(crate) fn check_receivers(receivers: usize, requests: &[ViewRequest]) -> Result<()> {
    match requests.iter().find(|r| r.receiver as usize >= receivers) {
        Some(r) => Err(Error::argument("receiver", format!("id {} out of range ({receivers} receivers)", r.receiver))),
        None => Ok(()),
    }
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
