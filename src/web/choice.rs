//! The JS API's `engine` option (`createEngine({ engine })`): which engine answers a page's views.
//!
//! Owns the split of a batch of views between the exact engine (single-threaded here: the wasm
//! runs in one worker) and the engine's GPU lane, and the web's rule for `auto`: no probe runs
//! in a page, so `auto` routes by [`simple_route`] (light views clipped, heavy or see-through
//! ones counted on the GPU), never by timing, so a page's answers do not depend on its load.

use crate::count::exact::engine::ExactEngine;
use crate::count::hybrid::{EngineKind, Route, Split, simple_route};
use crate::count::lanes::Lane;
use crate::count::{Engine, ViewAnswer, ViewRequest};
use crate::error::Result;
use crate::scene::Scene;

/// The chosen engine over one model: its exact engine (made on first use) and its GPU lane.
pub(super) struct Chosen<'a> {
    pub kind: EngineKind,
    pub scene: &'a Scene,
    pub exact: &'a std::cell::OnceCell<ExactEngine>,
    pub lane: Lane<'a>,
}

impl Chosen<'_> {
    fn exact(&self) -> &ExactEngine {
        self.exact.get_or_init(|| ExactEngine::new(self.scene))
    }
}

impl Engine for Chosen<'_> {
    fn batch(&self) -> usize {
        self.lane.batch()
    }

    async fn answer(&self, requests: &[ViewRequest]) -> Result<Vec<ViewAnswer>> {
        let (routes, clipped): (Vec<Route>, Option<Vec<f64>>) = match self.kind {
            EngineKind::Gpu => return self.lane.answer(requests).await,
            EngineKind::Exact => (vec![Route::Exact; requests.len()], None),
            EngineKind::Auto => {
                // One walk a view: its load routes it, and a view routed exact is clipped from it.
                let walked = self.exact().fractions_unless(requests, |load| simple_route(load) == Route::Gpu);
                let routes = walked.iter().map(|(_, f)| if f.is_some() { Route::Exact } else { Route::Gpu }).collect();
                (routes, Some(walked.into_iter().filter_map(|(_, f)| f).collect()))
            }
        };
        let split = Split::new(requests, &routes, None);
        let exact = match clipped {
            Some(clipped) => clipped,
            None if split.exact_reqs.is_empty() => Vec::new(),
            None => split.exact_fractions(self.exact()),
        };
        let gpu = if split.gpu_reqs.is_empty() { Vec::new() } else { self.lane.answer(&split.gpu_reqs).await? };
        Ok(split.merge(self.scene, requests, exact, gpu))
    }
}
