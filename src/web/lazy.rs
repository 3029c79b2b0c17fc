//! The page's GPU, opened only when a view is routed to it.
//!
//! `createEngine` learns the adapter (its name keys `auto`'s profiles, its limits check the
//! options) but opens no device, and loading a model uploads nothing: on SwiftShader the device
//! and its pipelines cost a first visit 0.14-0.39 s of CPU that `auto` never repays when its
//! profile clips every view (docs/page-speed.md). As natively, the device is made when the probe
//! wants the GPU or a view is routed to it, and a scene is uploaded on its first such view.

use std::cell::OnceCell;

use crate::count::gpu::{Adapter, Counter, CounterOptions, GpuScene};
use crate::count::lanes::Lane;
use crate::error::{Error, Result};
use crate::scene::Scene;

/// The page's WebGPU adapter and, once a view needs it, its counter.
pub(super) struct Gpu {
    adapter: Adapter,
    info: wgpu::AdapterInfo,
    options: CounterOptions,
    counter: OnceCell<Counter>,
}

impl Gpu {
    /// Finds the adapter, refusing options it cannot meet; opens no device.
    pub(super) async fn request(options: CounterOptions) -> Result<Self> {
        let adapter = Adapter::request(&options).await?;
        Ok(Self { info: adapter.info(), adapter, options, counter: OnceCell::new() })
    }

    /// The adapter's name, backend and device type.
    pub(super) fn info(&self) -> &wgpu::AdapterInfo {
        &self.info
    }

    /// Views per GPU batch, the same before and after the device is opened.
    pub(super) fn tiles_per_batch(&self) -> usize {
        self.adapter.tiles_per_batch(&self.options)
    }

    /// The counter, its device opened on first use.
    pub(super) async fn counter(&self) -> Result<&Counter> {
        if self.counter.get().is_none() {
            let opened = Counter::on(&self.adapter, self.options).await?;
            // Two calls may open one each while awaiting: the first kept is the only one used.
            let _ = self.counter.set(opened);
        }
        self.counter.get().ok_or_else(|| Error::argument("engine", "the GPU device went missing"))
    }
}

/// A scene's way onto the page's GPU: its upload, made on its first GPU view and kept beside the
/// scene.
#[derive(Clone, Copy)]
pub(super) struct Upload<'a> {
    pub gpu: &'a Gpu,
    pub scene: &'a Scene,
    pub uploaded: &'a OnceCell<GpuScene>,
}

impl<'a> Upload<'a> {
    /// The scene's lane, opening the device and uploading the scene if not done yet.
    pub(super) async fn lane(&self) -> Result<Lane<'a>> {
        let counter = self.gpu.counter().await?;
        if self.uploaded.get().is_none() {
            let _ = self.uploaded.set(counter.upload(self.scene)?);
        }
        let gpu = self.uploaded.get().ok_or_else(|| Error::argument("model", "its GPU upload went missing"))?;
        Ok(Lane { counter, gpu })
    }
}
