//! The one place where native and web differ: instance set-up and waiting for GPU → CPU reads.
//!
//! Natively the thread blocks in `Device::poll` until the map completes; on the web `poll` is a
//! no-op and blocking would freeze the page, so the map's callback completes a future instead.

use crate::error::{GpuError, Result};

/// The wgpu instance for this platform: the browser's WebGPU on the web; natively Vulkan, Metal
/// or DX12, overridable with `WGPU_BACKEND` (e.g. `vulkan`).
pub(crate) fn instance() -> wgpu::Instance {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    if cfg!(target_arch = "wasm32") {
        desc.backends = wgpu::Backends::BROWSER_WEBGPU;
    } else if wgpu::Backends::from_env().is_none() {
        desc.backends = wgpu::Backends::PRIMARY;
    }
    wgpu::Instance::new(desc)
}

/// wgpu's no-op backend, reporting `limits` (`None`: the largest) and every feature: passes are
/// recorded but never run, so only the host's work is timed. Native only; the browser has none.
#[cfg(not(target_arch = "wasm32"))]
pub(crate) fn noop_instance(limits: Option<wgpu::Limits>) -> Result<wgpu::Instance> {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    desc.backends = wgpu::Backends::NOOP;
    // wgpu 30's indirect-draw validation asserts a storage offset alignment of 32 to 256 bytes,
    // and the noop adapter's own limits give 1 (it panics at the first indirect draw): 32 is the
    // finest it accepts, and the counter binds no storage at an offset.
    let mut limits = limits.unwrap_or_else(wgpu::Limits::unlimited);
    limits.min_storage_buffer_offset_alignment = limits.min_storage_buffer_offset_alignment.max(32);
    desc.backend_options.noop = wgpu::NoopBackendOptions { limits: Some(limits), ..wgpu::NoopBackendOptions::enabled() };
    Ok(wgpu::Instance::new(desc))
}

/// The browser offers no no-op backend: asking for it is a parameter error.
#[cfg(target_arch = "wasm32")]
pub(crate) fn noop_instance(_limits: Option<wgpu::Limits>) -> Result<wgpu::Instance> {
    Err(crate::error::Error::argument("backend", "the no-op backend exists only natively, not in the browser"))
}

/// A stopwatch for host-time accounting: natively a monotonic clock; on the web, where
/// `Instant::now` panics and the counter must not depend on the page's clock, it always reads 0.
pub(crate) struct Stopwatch {
    #[cfg(not(target_arch = "wasm32"))]
    start: std::time::Instant,
}

impl Stopwatch {
    /// Starts timing.
    pub(crate) fn start() -> Self {
        Self {
            #[cfg(not(target_arch = "wasm32"))]
            start: std::time::Instant::now(),
        }
    }

    /// Nanoseconds since [`Self::start`] (0 on the web).
    pub(crate) fn nanos(&self) -> u64 {
        #[cfg(not(target_arch = "wasm32"))]
        return self.start.elapsed().as_nanos().min(u64::MAX as u128) as u64;
        #[cfg(target_arch = "wasm32")]
        0
    }
}

/// Seconds since some fixed point, for timing engines. Natively a monotonic clock. On the web the
/// global scope's `performance.now()` (a window's or a worker's: Chrome coarsens it to 100 µs),
/// and `Date.now()` (1 ms) only where that is missing: at 1 ms every light view timed 0 µs, and
/// the probe then priced a model's views at nothing.
pub(crate) fn seconds() -> f64 {
    #[cfg(not(target_arch = "wasm32"))]
    {
        use std::sync::OnceLock;
        static START: OnceLock<std::time::Instant> = OnceLock::new();
        START.get_or_init(std::time::Instant::now).elapsed().as_secs_f64()
    }
    #[cfg(target_arch = "wasm32")]
    {
        performance_now_ms().unwrap_or_else(js_sys::Date::now) / 1e3
    }
}

/// This process's CPU seconds (user + system, every thread) since it started, so a stage's CPU
/// against its wall time says how many cores its threads kept busy. On Unix `getrusage`; on the
/// web, where the views run on one thread, the clock's [`seconds`] (a stage's CPU reads as its
/// wall time); elsewhere the same stand-in.
pub(crate) fn cpu_seconds() -> f64 {
    #[cfg(all(unix, not(target_arch = "wasm32")))]
    {
        let mut usage = std::mem::MaybeUninit::<libc::rusage>::zeroed();
        // SAFETY: getrusage fills the whole rusage it is pointed at, or fails and we read nothing.
        if unsafe { libc::getrusage(libc::RUSAGE_SELF, usage.as_mut_ptr()) } != 0 {
            return 0.0;
        }
        // SAFETY: zeroed, then written by getrusage above.
        let usage = unsafe { usage.assume_init() };
        let secs = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
        secs(usage.ru_utime) + secs(usage.ru_stime)
    }
    #[cfg(not(all(unix, not(target_arch = "wasm32"))))]
    {
        seconds()
    }
}

/// The shortest interval [`seconds`] times well enough to route by: natively 0; on the web five
/// ticks of Chrome's coarsened clock, so a probe repeats a light view until it has run this long
/// (48 probed views then cost the first visit some 25 ms, not the probe's whole 0.15 s).
pub(crate) const CLOCK_FLOOR_S: f64 = if cfg!(target_arch = "wasm32") { 5e-4 } else { 0.0 };

/// `performance.now()` of whatever global scope runs this (window or worker), if it has one.
#[cfg(target_arch = "wasm32")]
fn performance_now_ms() -> Option<f64> {
    use wasm_bindgen::JsCast;
    let performance = js_sys::Reflect::get(&js_sys::global(), &"performance".into()).ok()?;
    let now: js_sys::Function = js_sys::Reflect::get(&performance, &"now".into()).ok()?.dyn_into().ok()?;
    now.call0(&performance).ok()?.as_f64()
}

/// What to tell a user who has no adapter at all.
pub(crate) fn no_adapter_hint() -> &'static str {
    if cfg!(target_arch = "wasm32") {
        "this browser offers no WebGPU adapter (try a current Chrome or Edge, or enable WebGPU)"
    } else {
        "no GPU adapter found; on Debian install a software Vulkan driver with `apt-get install mesa-vulkan-drivers`"
    }
}

/// Maps `buffer` (MAP_READ) and copies out its first `size` bytes.
pub(crate) async fn read_buffer(device: &wgpu::Device, buffer: &wgpu::Buffer, size: u64) -> Result<Vec<u8>> {
    let slice = buffer.slice(..size);
    let (sender, receiver) = futures_channel::oneshot::channel();
    slice.map_async(wgpu::MapMode::Read, move |result| {
        // The receiver only goes away if the caller was dropped; nothing to report then.
        let _ = sender.send(result);
    });
    wait_for_maps(device)?;
    receiver
        .await
        .map_err(|_| GpuError::Readback("the GPU device went away while reading results".into()))?
        .map_err(|e| GpuError::Readback(format!("reading results back failed: {e}")))?;
    let bytes = slice.get_mapped_range().map_err(|e| GpuError::Readback(format!("mapping results failed: {e}")))?.to_vec();
    buffer.unmap();
    Ok(bytes)
}

#[cfg(not(target_arch = "wasm32"))]
fn wait_for_maps(device: &wgpu::Device) -> Result<()> {
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| GpuError::Readback(format!("waiting for the GPU failed: {e}")).into())
}

#[cfg(target_arch = "wasm32")]
fn wait_for_maps(_device: &wgpu::Device) -> Result<()> {
    // The browser resolves the map on its own event loop; the future above is awaited instead.
    Ok(())
}

/// Runs `job` on every item at once and returns the results in item order: natively one thread
/// per item (each blocks on its own device); on the web, where there are no threads to block,
/// one after the other.
#[cfg(not(target_arch = "wasm32"))]
pub(crate) async fn side_by_side<I, T, F, Fut>(items: &[I], job: F) -> Vec<T>
where
    I: Sync,
    T: Send,
    F: Fn(&I) -> Fut + Sync,
    Fut: std::future::Future<Output = T>,
{
    if let [only] = items {
        return vec![job(only).await];
    }
    std::thread::scope(|scope| {
        let handles: Vec<_> = items.iter().map(|item| scope.spawn(|| pollster::block_on(job(item)))).collect();
        // A panicking lane is a bug; carry its panic to the caller rather than invent a result.
        handles.into_iter().map(|h| h.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))).collect()
    })
}

#[cfg(target_arch = "wasm32")]
pub(crate) async fn side_by_side<I, T, F, Fut>(items: &[I], job: F) -> Vec<T>
where
    F: Fn(&I) -> Fut,
    Fut: std::future::Future<Output = T>,
{
    let mut out = Vec::with_capacity(items.len());
    for item in items {
        out.push(job(item).await);
    }
    out
}

#[cfg(all(test, unix, not(target_arch = "wasm32")))]
mod tests {
    #![allow(clippy::unwrap_used)] // Tests may panic on the unexpected.
    use super::*;

    /// This process's CPU seconds as the kernel's own `/proc/self/stat` gives them (utime +
    /// stime, in clock ticks of 10 ms).
    fn proc_cpu_seconds() -> f64 {
        let stat = std::fs::read_to_string("/proc/self/stat").unwrap();
        // The command name may hold spaces: the fields counted after its closing parenthesis.
        let fields: Vec<&str> = stat[stat.rfind(')').unwrap() + 2..].split(' ').collect();
        let ticks = |i: usize| fields[i].parse::<f64>().unwrap();
        // utime and stime are fields 14 and 15 of stat, 12 and 13 after the name and state.
        (ticks(11) + ticks(12)) / 100.0
    }

    /// `cpu_seconds` is the process's CPU, not the clock: after some work, and again after a
    /// sleep (which moves the clock, not the CPU), it reads what the kernel's `/proc/self/stat`
    /// reads, to its 10 ms ticks plus what other test threads spend between the two reads.
    #[test]
    fn cpu_seconds_are_the_kernels_cpu_time_not_the_clock() {
        let start = std::time::Instant::now();
        let mut x = 1u64;
        while proc_cpu_seconds() < 0.3 && start.elapsed().as_secs() < 60 {
            for _ in 0..100_000 {
                x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
            }
        }
        let (ours, kernels) = (cpu_seconds(), proc_cpu_seconds());
        assert!(kernels >= 0.3, "spun for a minute without 0.3 s of CPU: {kernels}");
        assert!((ours - kernels).abs() < 0.2, "cpu_seconds {ours} against /proc/self/stat's {kernels}");
        std::thread::sleep(std::time::Duration::from_millis(1500));
        let (ours, kernels) = (cpu_seconds(), proc_cpu_seconds());
        assert!((ours - kernels).abs() < 0.2, "after a 1.5 s sleep: cpu_seconds {ours} against /proc/self/stat's {kernels}");
    }
}
