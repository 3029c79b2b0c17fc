//! The clipping half of the web engine, for the pool's workers (`www/pool.js`,
//! `www/clip-worker.js`): a model's exact engine without any GPU, and its fractions for packed
//! requests. Each worker holds its own wasm instance and its own [`Clipper`]; the scene itself
//! is dropped once indexed, so a worker keeps only what clipping reads.

use js_sys::Float64Array;
use wasm_bindgen::prelude::*;

use super::choice::unpack;
use super::js_error;
use crate::count::exact::engine::ExactEngine;
use crate::scene::Scene;

/// A model's exact engine, built from the engine's own scene.
#[wasm_bindgen]
pub struct Clipper {
    exact: ExactEngine,
    receivers: usize,
}

#[wasm_bindgen]
impl Clipper {
    /// From the engine's scene as `Model.sceneBytes` encodes it ([`Scene::to_bytes`]): no model
    /// file is read again. With `objects` (`Model.objectsBytes`, the engine's convex objects over
    /// that scene), the worker takes them instead of grouping the triangles itself, the step that
    /// set its peak memory. Each byte list is dropped once decoded, the scene once indexed.
    #[wasm_bindgen(js_name = fromScene)]
    pub fn from_scene(bytes: Vec<u8>, objects: Option<Vec<u8>>) -> Result<Clipper, JsValue> {
        let scene = Scene::from_bytes(&bytes).map_err(js_error)?;
        drop(bytes);
        let exact = match objects {
            Some(objects) => ExactEngine::with_objects(&scene, &objects).map_err(js_error)?,
            None => ExactEngine::new(&scene),
        };
        Ok(Clipper { exact, receivers: scene.receivers.len() })
    }

    /// The sunlit fraction of each packed request (receiver, sun x, y, z, leaf fraction), exact.
    pub fn fractions(&self, packed: &[f64]) -> Result<Float64Array, JsValue> {
        clip(&self.exact, self.receivers, packed)
    }
}

/// `exact`'s fractions of packed requests over a scene of `receivers` receivers: a worker's, or
/// the engine's own thread's where it clips beside its workers (`Model.clipHere`).
pub(super) fn clip(exact: &ExactEngine, receivers: usize, packed: &[f64]) -> Result<Float64Array, JsValue> {
    let requests = unpack(packed, receivers).map_err(js_error)?;
    Ok(Float64Array::from(exact.fractions(&requests).as_slice()))
}
