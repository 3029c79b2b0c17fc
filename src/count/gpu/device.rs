//! The GPU device: opening an adapter and a device within its limits, and watching it for
//! failures.
//!
//! wgpu reports most failures asynchronously, to an uncaptured-error handler, and a lost device
//! to a callback; [`Faults`] records both, and the counter asks it after each stage, so every
//! failure surfaces as a typed [`Error`] of the stage that caused it: a lost device as
//! [`Error::DeviceLost`] (every later error is its consequence), out-of-memory as
//! [`GpuError::OutOfMemory`] (found by its wgpu variant, not its text), the rest as
//! [`GpuError::Validation`].

use std::sync::{Arc, Mutex};

use super::{Backend, CounterOptions};
use crate::error::{Error, GpuError, Result};
use crate::platform;

/// An open device and what it came from.
pub(super) struct Opened {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    /// Tiles along the atlas's side at `resolution`, within the device's texture limit.
    pub tiles_per_side: u32,
    /// What the adapter can do beyond WebGPU's core (indirect draws, storage in vertex shaders).
    pub downlevel: wgpu::DownlevelFlags,
}

/// The platform's default adapter, its limits checked against a counter's options, before any
/// device is opened (the page learns its adapter at once and opens the device only when a view
/// is routed to it).
#[derive(Clone)]
pub struct Adapter {
    adapter: wgpu::Adapter,
    limits: wgpu::Limits,
    tiles_per_side: u32,
}

impl Adapter {
    /// Asks for the platform's default adapter, refusing options it cannot meet (a resolution
    /// above its texture size) before allocating anything.
    pub async fn request(options: &CounterOptions) -> Result<Self> {
        let profile = options.limits.limits();
        let instance = match options.backend {
            Backend::Platform => platform::instance(),
            Backend::Noop => platform::noop_instance(profile.clone())?,
        };
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions::default())
            .await
            .map_err(|e| GpuError::NoAdapter { hint: platform::no_adapter_hint().into(), reason: e.to_string() })?;
        // A profile asks for no more than the named class offers, and never more than the adapter.
        let limits = match &profile {
            Some(profile) => adapter.limits().or_worse_values_from(profile),
            None => adapter.limits(),
        };
        let resolution = options.resolution;
        if !(16..=limits.max_texture_dimension_2d).contains(&resolution) {
            return Err(Error::argument(
                "resolution",
                format!("{resolution} is outside 16..={} (this device's texture size limit)", limits.max_texture_dimension_2d),
            ));
        }
        if let Some(a) = options.accuracy
            && !(a > 0.0 && a < 1.0)
        {
            return Err(Error::argument("accuracy", format!("{a} is not a fraction error in (0, 1)")));
        }
        let tiles_per_side = options.max_atlas.clamp(resolution, limits.max_texture_dimension_2d) / resolution;
        Ok(Self { adapter, limits, tiles_per_side })
    }

    /// The adapter's name, backend and device type.
    pub fn info(&self) -> wgpu::AdapterInfo {
        self.adapter.get_info()
    }

    /// Views per batch a counter opened on this adapter at `options` takes
    /// ([`super::Counter::tiles_per_batch`]), known before its device is opened.
    pub fn tiles_per_batch(&self, options: &CounterOptions) -> usize {
        super::plan::tiles_at(self.tiles_per_side * options.resolution, options.resolution)
    }
}

/// Opens a device on `adapter` with all its (checked) limits.
pub(super) async fn open_on(adapter: &Adapter) -> Result<Opened> {
    let (device, queue) = adapter
        .adapter
        .request_device(&wgpu::DeviceDescriptor { label: Some("sunlit"), required_limits: adapter.limits.clone(), ..Default::default() })
        .await
        .map_err(|e| GpuError::Device(e.to_string()))?;
    let downlevel = adapter.adapter.get_downlevel_capabilities().flags;
    Ok(Opened { device, queue, info: adapter.info(), tiles_per_side: adapter.tiles_per_side, downlevel })
}

/// What the uncaptured-error handler records: out-of-memory apart, so it gets its own error.
#[derive(Debug, PartialEq)]
enum Uncaptured {
    OutOfMemory,
    Other(String),
}

/// A device's failures as they are reported: uncaptured errors and its loss.
pub(super) struct Faults {
    errors: Arc<Mutex<Vec<Uncaptured>>>,
    /// Why the device was lost, once it is (set by wgpu's device-lost callback).
    lost: Arc<Mutex<Option<String>>>,
}

impl Faults {
    /// Starts recording `device`'s uncaptured errors and its loss.
    pub fn watch(device: &wgpu::Device) -> Self {
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut list) = sink.lock() {
                list.push(if matches!(e, wgpu::Error::OutOfMemory { .. }) {
                    Uncaptured::OutOfMemory
                } else {
                    Uncaptured::Other(e.to_string())
                });
            }
        }));
        let lost = Arc::new(Mutex::new(None));
        let lost_sink = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            if let Ok(mut slot) = lost_sink.lock() {
                *slot = Some(format!("{reason:?}: {message}"));
            }
        });
        Self { errors, lost }
    }

    /// The first failure recorded since the last check, as the error of stage `doing` (the
    /// loss first: every later error is a consequence of it). `resolution` goes into the
    /// out-of-memory error, which suggests lowering it.
    pub fn check(&self, doing: &str, resolution: u32) -> Result<()> {
        self.check_lost()?;
        let mut list = self
            .errors
            .lock()
            .map_err(|_| GpuError::Validation { doing: doing.into(), message: "the error log was poisoned by a panic".into() })?;
        if list.is_empty() {
            return Ok(());
        }
        let error = if list.contains(&Uncaptured::OutOfMemory) {
            GpuError::OutOfMemory { doing: doing.into(), resolution }
        } else {
            let all: Vec<&str> = list.iter().filter_map(|e| if let Uncaptured::Other(m) = e { Some(m.as_str()) } else { None }).collect();
            GpuError::Validation { doing: doing.into(), message: all.join("; ") }
        };
        list.clear();
        Err(error.into())
    }

    /// [`Error::DeviceLost`] once the device is gone.
    pub fn check_lost(&self) -> Result<()> {
        match self.lost.lock().map(|l| l.clone()) {
            Ok(Some(why)) => Err(Error::DeviceLost(why)),
            _ => Ok(()),
        }
    }
}
