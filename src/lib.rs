//! # sunlit
//!
//! Sunlit fractions of building surfaces (sunlit area / area, 0..1) for any sun direction, by
//! pixel counting on the GPU after Jones, Greenberg & Reinhart (Building Simulation 2011): for a
//! receiving surface and a sun direction, render the scene with an orthographic camera looking
//! along the sun's rays, fitted tightly to the surface, and count the surface's visible pixels.
//!
//! The modules follow the pipeline:
//! - [`model`]: model files in (glTF/glb) and out (glb writer for examples and benchmarks);
//! - [`scene`]: triangles that cast shadows and planar receivers, laid out for the GPU;
//! - [`sun`]: sun positions and directions;
//! - [`count`]: the GPU pixel counter and the exact CPU polygon-clipping reference.
//! - [`season`]: the leaf calendar that foliage follows through the year.
//!
//! ```no_run
//! # fn main() -> sunlit::Result<()> {
//! use sunlit::{model, count::{gpu::Counter, ViewRequest}, sun::SunPosition};
//! let scene = model::load(&["examples/office.glb".into()], &model::LoadOptions::default())?;
//! let sun = SunPosition::new(180.0, 40.0)?.direction();
//! let requests: Vec<ViewRequest> = (0..scene.receivers.len() as u32).map(|receiver| ViewRequest::new(receiver, sun)).collect();
//! let counter = pollster::block_on(Counter::new(Default::default()))?;
//! let fractions = pollster::block_on(counter.fractions(&counter.upload(&scene)?, &requests))?;
//! # Ok(()) }
//! ```

#[cfg(feature = "fixtures")]
pub mod bench;
pub mod count;
pub mod error;
pub mod export;
pub mod geometry;
pub mod model;
mod platform;
pub mod scene;
pub mod sun;
#[cfg(target_arch = "wasm32")]
pub mod web;
pub mod year;

pub use error::{Error, Result};
