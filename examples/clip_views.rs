//! The native half of `scripts/bench-wasm-clip.mjs`: the exact engine over the same scene,
//! objects and views the page's wasm clipper was timed on, on one thread, and whether its
//! fractions equal the wasm's bit for bit.
//!
//! ```sh
//! node scripts/bench-wasm-clip.mjs oc.glb --out /tmp/clip
//! taskset -c 0 cargo run --release --example clip_views -- /tmp/clip [REPEAT]
//! ```

use std::time::Instant;

use sunlit::count::ViewRequest;
use sunlit::count::exact::engine::ExactEngine;
use sunlit::scene::Scene;

fn f64s(bytes: &[u8]) -> Vec<f64> {
    bytes.chunks_exact(8).map(|b| f64::from_le_bytes(b.try_into().unwrap_or([0; 8]))).collect()
}

/// This thread's CPU time in seconds (Linux's schedstat), so a loaded machine's waits are not
/// counted; with `taskset -c 0` the engine runs on this one thread.
fn thread_cpu() -> f64 {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap_or_default();
    stat.split_whitespace().next().and_then(|ns| ns.parse::<f64>().ok()).unwrap_or(f64::NAN) / 1e9
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let dir = args.next().ok_or("usage: clip_views DIR [REPEAT]")?;
    let repeat: usize = args.next().map_or(Ok(1), |r| r.parse())?;
    let scene = Scene::from_bytes(&std::fs::read(format!("{dir}/scene.bin"))?)?;
    let objects = std::fs::read(format!("{dir}/objects.bin"))?;
    let packed = f64s(&std::fs::read(format!("{dir}/views.f64"))?);
    let wasm = f64s(&std::fs::read(format!("{dir}/wasm.f64"))?);
    let requests: Vec<ViewRequest> = packed
        .chunks_exact(5)
        .map(|p| ViewRequest::new(p[0] as u32, glam::DVec3::new(p[1], p[2], p[3])).with_leaves(p[4] as f32))
        .collect();
    let exact = ExactEngine::with_objects(&scene, &objects)?;
    let mut times = Vec::new();
    let mut fractions = Vec::new();
    for _ in 0..repeat {
        let (t, cpu) = (Instant::now(), thread_cpu());
        fractions = exact.fractions(&requests);
        times.push((thread_cpu() - cpu, t.elapsed().as_secs_f64()));
    }
    times.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (median, wall) = times[times.len() / 2];
    let differ = fractions.iter().zip(&wasm).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
    let max_diff = fractions.iter().zip(&wasm).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    println!(
        "{{\"views\": {}, \"cpu_s\": {median:.3}, \"wall_s\": {wall:.3}, \"us_per_view\": {:.1}, \"differ_from_wasm\": {differ}, \"max_abs_diff\": {max_diff:e}}}",
        requests.len(),
        median / requests.len() as f64 * 1e6
    );
    Ok(())
}
