//! # sunlit
//!
//! Sunlit fractions of building surfaces (sunlit area / area, 0..1) for any sun direction, by
//! pixel counting on the GPU after Jones, Greenberg & Reinhart (Building Simulation 2011): for a
//! receiving surface and a sun direction, render the scene with an orthographic camera looking
//! along the sun's rays, fitted tightly to the surface, and count the surface's visible pixels.
//!
//! The modules follow the pipeline, one stage a folder or file:
//! - [`model`]: model files in (glTF/glb, EnergyPlus IDF/epJSON, typed arrays);
//! - [`scene`]: triangles that cast shadows and planar receivers, laid out for the GPU;
//! - [`geometry`]: planar geometry the readers, the scene and the hook share;
//! - [`sun`]: locations, sun positions and directions, and the EPW weather;
//! - [`sky`]: sky patches, each receiver's sky views and the Perez sky;
//! - [`count`]: one request and one answer ([`count::ViewRequest`], [`count::ViewAnswer`]) and
//!   the engines that answer it: the GPU pixel counter ([`count::gpu`]) and the exact CPU
//!   polygon-clipping reference ([`count::exact`]);
//! - [`map`]: points on receivers (a grid or a CSV) and, per point, the sun seen at an instant
//!   (by a shadow ray, or by its texel in the GPU counter's tile), sun hours and direct
//!   irradiation over a period, and sun-hours studies;
//! - [`year`]: sampling plan, leaf calendar, the settings resolver, the spline and the annual run;
//! - [`export`]: the EnergyPlus CSV, the model hooked to it, and the irradiation summary;
//! - [`error`]: the one typed error, naming parameters, files and objects;
//! - `sweep` (native only): many annual runs from a manifest, locally or as a Slurm job array.
//!
//! Two thin edges drive it: the CLI (`src/main.rs`) and the wasm-bindgen API (`web`, wasm
//! only). With the `fixtures` feature (the CLI's), `bench` and `model::{office, office_idf,
//! glb_write}` generate example and benchmark models; the wasm bundle is built without them.
//!
//! ```no_run
//! # fn main() -> sunlit::Result<()> {
//! use sunlit::{model, count::{self, Engine, gpu::Counter, ViewRequest}, sun::SunPosition};
//! let scene = model::load(&["examples/office.glb".into()], &model::LoadOptions::default())?;
//! let sun = SunPosition::new(180.0, 40.0)?.direction();
//! let requests: Vec<ViewRequest> = (0..scene.receivers.len() as u32).map(|receiver| ViewRequest::new(receiver, sun)).collect();
//! let counter = pollster::block_on(Counter::new(Default::default()))?;
//! let gpu = counter.upload(&scene)?;
//! // The GPU or the exact reference: both are a count::Engine.
//! let answers = pollster::block_on(count::lanes::Lane { counter: &counter, gpu: &gpu }.answer(&requests))?;
//! let exact = pollster::block_on(count::exact::Exact { scene: &scene }.answer(&requests))?;
//! # Ok(()) }
//! ```

#[cfg(feature = "fixtures")]
pub mod bench;
pub mod count;
pub mod error;
pub mod export;
pub mod geometry;
#[cfg(test)]
mod js_api;
pub mod map;
pub mod model;
mod platform;
pub mod scene;
pub mod sky;
pub mod sun;
#[cfg(not(target_arch = "wasm32"))]
pub mod sweep;
#[cfg(target_arch = "wasm32")]
pub mod web;
pub mod year;

pub use error::{Error, Result};
