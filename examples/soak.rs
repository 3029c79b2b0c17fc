//! Soak: many annual computations in one process, printing resident memory as it goes, to show
//! that repeated runs (new uploads, one counter) do not grow memory.
//!
//! ```text
//! cargo run --release --example soak -- [RUNS] [RESOLUTION]
//! ```
//! Defaults: 200 runs at 64 px on the example office (2 louvres), a 6 × 7 sampling plan, one
//! timestep per hour. Prints one JSON line per 20 runs: run, seconds, VmRSS and VmHWM in MiB.

use std::error::Error;
use std::time::Instant;

use sunlit::count::gpu::{Counter, CounterOptions};
use sunlit::model::{LoadOptions, load_bytes, office::office};
use sunlit::sun::location::Location;
use sunlit::year::annual::{AnnualOptions, Method, annual_recovering};
use sunlit::year::samples::{SamplingPlan, Timesteps};

fn main() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let runs: usize = args.next().map(|a| a.parse()).transpose()?.unwrap_or(200);
    let resolution: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(64);
    let scene = load_bytes(&[("office.glb".into(), office(2).to_glb())], &LoadOptions::default())?;
    let location = Location::new(39.74, -105.18, -7.0)?;
    let options = AnnualOptions {
        timesteps: Timesteps::new(1)?,
        method: Method::Spline(SamplingPlan::new(6, 7)?),
        refine: 1.0,
        prove_never_dark: false,
        many_casters: Some(false),
        inner_corners: false,
    };
    let counter = pollster::block_on(Counter::new(CounterOptions { resolution, ..Default::default() }))?;
    let gpu = counter.upload(&scene)?;
    let mut lanes = vec![(counter, gpu)];
    let start = Instant::now();
    let mut first = None;
    for run in 1..=runs {
        // A fresh upload per run, as the page and the CLI do per computation.
        lanes[0].1 = lanes[0].0.upload(&scene)?;
        let schedule = pollster::block_on(annual_recovering(
            &mut lanes,
            &scene,
            &location,
            &options,
            &sunlit::year::season::LeafCalendar::evergreen(),
            &mut |_| Ok(()),
        ))?;
        let sum: f64 = schedule.values.iter().map(|&v| v as f64).sum();
        // Every run must give the same year; a drifting sum would be a leak of another kind.
        let first_sum = *first.get_or_insert(sum);
        if (sum - first_sum).abs() > 1e-6 * first_sum.abs().max(1.0) {
            return Err(format!("run {run}: sum {sum} differs from the first run's {first_sum}").into());
        }
        if run == 1 || run % 20 == 0 {
            let (rss, hwm) = memory();
            println!(r#"{{"run": {run}, "seconds": {:.1}, "rss_mib": {rss:.1}, "hwm_mib": {hwm:.1}}}"#, start.elapsed().as_secs_f64());
        }
    }
    Ok(())
}

/// (VmRSS, VmHWM) in MiB from /proc/self/status (0 where unavailable).
fn memory() -> (f64, f64) {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let field = |name: &str| {
        status
            .lines()
            .find_map(|l| l.strip_prefix(name))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
            .map_or(0.0, |kb| kb / 1024.0)
    };
    (field("VmRSS:"), field("VmHWM:"))
}
