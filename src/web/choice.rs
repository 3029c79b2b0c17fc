//! The JS API's `engine` option (`createEngine({ engine })`): which engine answers a page's views.
//!
//! Owns the split of a batch of views between the exact engine (single-threaded here: the wasm
//! runs in one worker) and the engine's GPU lane, and the web's rule for `auto`: no probe runs
//! in a page, so `auto` routes by [`simple_route`] (light views clipped, heavy or see-through
//! ones counted on the GPU), never by timing, so a page's answers do not depend on its load.

use crate::count::exact::engine::{ExactEngine, ViewLoad};
use crate::count::hybrid::{EngineKind, Route, routed_to, simple_route};
use crate::count::lanes::Lane;
use crate::count::{Engine, ViewAnswer, ViewRequest, cos_incidence};
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
        let (routes, loads): (Vec<Route>, Option<Vec<ViewLoad>>) = match self.kind {
            EngineKind::Gpu => return self.lane.answer(requests).await,
            EngineKind::Exact => (vec![Route::Exact; requests.len()], None),
            EngineKind::Auto => {
                let loads = self.exact().loads(requests);
                (loads.iter().copied().map(simple_route).collect(), Some(loads))
            }
        };
        let (gpu_idx, gpu_reqs) = routed_to(requests, &routes, Route::Gpu);
        let (exact_idx, exact_reqs) = routed_to(requests, &routes, Route::Exact);
        let mut out: Vec<ViewAnswer> = requests
            .iter()
            .map(|r| ViewAnswer {
                cos_incidence: self.scene.receivers.get(r.receiver as usize).map_or(0.0, |s| cos_incidence(s.normal, r.sun)),
                ..Default::default()
            })
            .collect();
        if !exact_reqs.is_empty() {
            let fractions = match &loads {
                // Routing walked every view already: the exact engine skips those that reached nothing.
                Some(loads) => self.exact().fractions_loaded(&exact_reqs, &exact_idx.iter().map(|&i| loads[i]).collect::<Vec<_>>()),
                None => self.exact().fractions(&exact_reqs),
            };
            for (&i, fraction) in exact_idx.iter().zip(fractions) {
                out[i].fraction = fraction;
                out[i].error_estimate = Some(0.0);
            }
        }
        if !gpu_reqs.is_empty() {
            for (&i, answer) in gpu_idx.iter().zip(self.lane.answer(&gpu_reqs).await?) {
                out[i] = answer;
            }
        }
        Ok(out)
    }
}
