//! The clipping half of the web engine, for the pool's workers (`www/pool.js`,
//! `www/clip-worker.js`): a model's exact engine without any GPU, and its fractions for packed
//! requests. Each worker holds its own wasm instance and its own [`Clipper`]; the scene itself
//! is dropped once indexed, so a worker keeps only what clipping reads.

use js_sys::{Array, Float64Array};
use wasm_bindgen::prelude::*;

use super::choice::unpack;
use super::js_error;
use crate::count::exact::engine::ExactEngine;
use crate::model::arrays::{Arrays, scene_from_arrays};
use crate::model::placed::{Placed, scene_from_placed};
use crate::scene::Scene;

/// A model's exact engine, built from the same input as the engine's model.
#[wasm_bindgen]
pub struct Clipper {
    exact: ExactEngine,
    receivers: usize,
}

impl Clipper {
    fn of(scene: &Scene) -> Clipper {
        Clipper { exact: ExactEngine::new(scene), receivers: scene.receivers.len() }
    }
}

#[wasm_bindgen]
impl Clipper {
    /// As `Engine.loadFiles` (same arguments, same errors).
    #[wasm_bindgen(js_name = fromFiles)]
    pub fn from_files(
        names: Vec<String>,
        contents: Array,
        receivers: Option<String>,
        north: Option<f64>,
        foliage: Option<String>,
        transmittance: Option<String>,
    ) -> Result<Clipper, JsValue> {
        let loaded = super::load_files(names, contents, receivers, north, foliage, transmittance).map_err(js_error)?;
        Ok(Self::of(&loaded.scene))
    }

    /// From the engine's scene as `Model.sceneBytes` encodes it ([`Scene::to_bytes`]): no model
    /// file is read again. The bytes are dropped once decoded, the scene once indexed.
    #[wasm_bindgen(js_name = fromScene)]
    pub fn from_scene(bytes: Vec<u8>) -> Result<Clipper, JsValue> {
        let scene = Scene::from_bytes(&bytes).map_err(js_error)?;
        drop(bytes);
        Ok(Self::of(&scene))
    }

    /// As `Engine.fromArrays`.
    #[wasm_bindgen(js_name = fromArrays)]
    pub fn from_arrays(
        positions: &[f32],
        indices: &[u32],
        triangle_receivers: &[i32],
        names: Vec<String>,
        y_up: bool,
    ) -> Result<Clipper, JsValue> {
        let arrays = Arrays { positions, indices, triangle_receivers, names: &names, y_up };
        Ok(Self::of(&scene_from_arrays(&arrays).map_err(js_error)?))
    }

    /// As `Engine.fromMeshes`.
    #[wasm_bindgen(js_name = fromMeshes)]
    #[allow(clippy::too_many_arguments)]
    pub fn from_meshes(
        positions: &[f32],
        vertex_starts: &[u32],
        indices: &[u32],
        index_starts: &[u32],
        placement_meshes: &[u32],
        matrices: &[f64],
        names: Vec<String>,
        receivers: &[u8],
        y_up: bool,
    ) -> Result<Clipper, JsValue> {
        let input = Placed { positions, vertex_starts, indices, index_starts, placement_meshes, matrices, names: &names, receivers, y_up };
        Ok(Self::of(&scene_from_placed(&input).map_err(js_error)?))
    }

    /// The sunlit fraction of each packed request (receiver, sun x, y, z, leaf fraction), exact.
    pub fn fractions(&self, packed: &[f64]) -> Result<Float64Array, JsValue> {
        let requests = unpack(packed, self.receivers).map_err(js_error)?;
        Ok(Float64Array::from(self.exact.fractions(&requests).as_slice()))
    }
}
