//! `sunlit bench`, the CLI's edge of [`sunlit::bench`]: its flags, the generated or loaded models,
//! timing them on the GPU alone or on the hybrid engine, and one JSON line a model. The library
//! owns the models, the synthetic cases and the timing of views.

use super::*;

#[derive(Args)]
pub(super) struct BenchArgs {
    /// List the generated benchmark models and exit.
    #[arg(long)]
    list: bool,
    /// Write the one generated model named as glb and exit.
    #[arg(long, value_name = "FILE.glb")]
    write: Option<PathBuf>,
    /// Sampling plan for models: days per year × samples per day (the views `sunlit annual`
    /// counts for its spline, before refinement).
    #[arg(long, value_name = "DAYSxPER_DAY", default_value = "27x19")]
    samples: String,
    /// Time an even spread of at most this many of a model's views and extrapolate the total.
    #[arg(long, value_name = "N")]
    views: Option<usize>,
    /// Also check this many of the views counted on the GPU against the exact CPU reference, and
    /// (unless --engine gpu) as many exactly clipped ones; not timed.
    #[arg(long, value_name = "N", default_value_t = 0)]
    check: usize,
    /// Location of model files (generated models carry their own): latitude, longitude, time zone.
    #[arg(long, value_name = "LAT,LON,TZ", allow_hyphen_values = true, default_value = "39.74,-105.18,-7")]
    location: String,
    /// Occluder triangle counts for the synthetic cases (without models).
    #[arg(long, value_name = "N,…", value_delimiter = ',', default_values_t = [1_000usize, 100_000, 1_000_000])]
    triangles: Vec<usize>,
    /// Leaf counts for street-tree cases (trees in full leaf in front of a facade), e.g.
    /// 35905,233866 as in the paper's Blaas case; none by default (without models).
    #[arg(long, value_name = "N,…", value_delimiter = ',')]
    trees: Vec<usize>,
    /// Sun directions per synthetic case (without models).
    #[arg(long, value_name = "N", default_value_t = 64)]
    suns: usize,
    #[command(flatten)]
    pixels: PixelArgs,
    /// Largest atlas side in pixels (views per submission = (atlas / resolution)²).
    #[arg(long, value_name = "PIXELS", default_value_t = CounterOptions::default().max_atlas)]
    atlas: u32,
    /// Devices counting side by side, each with its own copy of the scene; default: 2 on a CPU
    /// rasterizer (lavapipe bins triangles on one thread a device) with 2 or more cores, else 1.
    #[arg(long, value_name = "N")]
    lanes: Option<usize>,
    #[command(flatten)]
    engine: EngineArgs,
    /// The GPU counter's adapter: `platform` (Vulkan, Metal, DX12) or `noop`, wgpu's no-op backend,
    /// whose passes are recorded but never run: `seconds / views_rendered` is then the host's cost
    /// a view. Counts read back as zeros there, so it takes neither --check nor --accuracy, and
    /// only with --engine gpu.
    #[arg(long, value_name = "platform|noop", default_value = "platform")]
    backend: String,
    /// Ask the device for no more than these limits: `adapter` (all it offers), `lavapipe`
    /// (Mesa's CPU driver as measured here) or `webgpu` (WebGPU's core limits, what a browser
    /// grants), so the fallbacks those devices take are timed on any adapter.
    #[arg(long, value_name = "adapter|lavapipe|webgpu", default_value = "adapter")]
    limits: String,
    /// Also time the GPU's culling pass (clusters of at most 128 triangles tested against every
    /// view of a batch of 1,024, on the GPU) over the same views, after the timed count: its
    /// figures go in a `gpu_cull` object. Only with --engine gpu or compute and models; no count
    /// depends on it yet.
    #[arg(long)]
    gpu_cull: bool,
    /// Where the raster kernel's views get their casters: `cpu` (the BVH walk, one draw per
    /// merged range), `gpu` (the GPU's culling pass, one indirect draw a view; the CPU's where
    /// the adapter or the scene cannot) or `gpu-batch` (the GPU's culling, one draw a batch).
    /// Only with --engine gpu. The JSON line's `cull` says which ran.
    #[arg(long, value_name = "cpu|gpu|gpu-batch", default_value = "cpu")]
    cull: String,
    /// Count what the compute kernel's raster tiles walk (tiles, list entries, triangles set up,
    /// rows, pixel centres tested) into the JSON line's `compute_walk`. Only with --engine
    /// compute; its atomics cost a little, so time without it.
    #[arg(long)]
    walk_stats: bool,
    /// Time each model's sky pass instead: every receiver's sky views over the given patch
    /// scheme (`tregenza` or `reinhart:N`), once, on the chosen engine.
    #[arg(long, value_name = "SCHEME")]
    sky: Option<String>,
    /// Generated model names (see --list) or model files (glTF, IDF, epJSON); none: the synthetic
    /// occluder clouds and the example office, at random suns.
    models: Vec<String>,
}

pub(super) fn run_bench(args: BenchArgs) -> Result<()> {
    if args.list {
        for (name, description) in bench::models::CATALOGUE {
            println!("{name:<20} {description}");
        }
        return Ok(());
    }
    if let Some(path) = &args.write {
        let [name] = args.models.as_slice() else {
            return Err(Error::argument("--write", "name exactly one generated model (see --list)"));
        };
        let model = bench::models::generate(name)?;
        std::fs::write(path, model.glb.to_glb()).map_err(|source| Error::Io { path: path.clone(), source })?;
        eprintln!("wrote {} ({} receivers, {} shading polygons)", path.display(), model.receivers, model.shading_polygons);
        return Ok(());
    }
    if args.suns == 0 {
        return Err(Error::argument("--suns", "must be at least 1"));
    }
    if args.gpu_cull && (args.models.is_empty() || args.sky.is_some()) {
        return Err(Error::argument("--gpu-cull", "times the culling over a model's sun views: name a model, without --sky"));
    }
    if let Some(scheme) = &args.sky {
        return bench_sky(&args, scheme);
    }
    let options = counter_options(&args)?;
    if !args.models.is_empty() && !args.engine.kind()?.gpu_only() {
        if options.backend == Backend::Noop {
            return Err(Error::argument("--backend", "noop times the GPU counter alone: use it with --engine gpu or compute"));
        }
        if args.gpu_cull {
            return Err(Error::argument("--gpu-cull", "times the GPU's culling pass: use it with --engine gpu or compute"));
        }
        let start = Instant::now();
        return bench_hybrid(&args, move || start.elapsed().as_secs_f64());
    }
    let made = Instant::now();
    let counter = pollster::block_on(Counter::new(options))?;
    let startup = made.elapsed().as_secs_f64();
    let info = counter.adapter_info();
    let limits = counter.limits();
    eprintln!(
        "adapter: {} ({:?}, {:?}), {} views per submission; limits: texture side {}, storage binding {} MiB, buffer {} bytes",
        info.name,
        info.backend,
        info.device_type,
        counter.tiles_per_batch(),
        limits.max_texture_dimension_2d,
        limits.max_storage_buffer_binding_size >> 20,
        limits.max_buffer_size
    );
    let start = Instant::now();
    let now = move || start.elapsed().as_secs_f64();
    if !args.models.is_empty() {
        return bench_models(&args, &counter, startup, now);
    }
    let suns = bench::suns(args.suns, 7);
    let mut cases: Vec<(String, Scene)> = Vec::new();
    for &n in &args.triangles {
        cases.push((format!("cloud {n}"), bench::occluder_cloud(n, 42)?));
    }
    for &n in &args.trees {
        let glb = bench::street_trees_glb(n, 11);
        cases.push((format!("street trees {n} leaves"), model::load_bytes(&[("trees.glb".into(), glb)], &LoadOptions::default())?));
    }
    let office = sunlit::model::office::office(6).to_glb();
    cases.push(("example office".into(), model::load_bytes(&[("office.glb".into(), office)], &LoadOptions::default())?));
    for (name, scene) in &cases {
        let t = pollster::block_on(bench::time_views(&counter, name, scene, &suns, now))?;
        println!("{}", serde_json::to_string(&t).map_err(|e| Error::Io { path: "stdout".into(), source: e.into() })?);
    }
    Ok(())
}

/// The counter's options from the pixel, atlas, backend and limits flags. The no-op backend reads
/// back zeros, so anything that acts on counts (checks, adaptive recounts) is refused with it.
fn counter_options(args: &BenchArgs) -> Result<CounterOptions> {
    let backend = match args.backend.as_str() {
        "platform" => Backend::Platform,
        "noop" => Backend::Noop,
        other => return Err(Error::argument("--backend", format!("'{other}' is not platform or noop"))),
    };
    let limits = match args.limits.as_str() {
        "adapter" => LimitsProfile::Adapter,
        "lavapipe" => LimitsProfile::Lavapipe,
        "webgpu" => LimitsProfile::WebGpuCore,
        other => return Err(Error::argument("--limits", format!("'{other}' is not adapter, lavapipe or webgpu"))),
    };
    let kernel = if args.engine.kind()? == EngineKind::Compute { Kernel::Compute } else { Kernel::Raster };
    let (gpu_cull, batch_draw) = match args.cull.as_str() {
        "cpu" => (false, false),
        "gpu" | "gpu-batch" if kernel == Kernel::Raster => (true, args.cull == "gpu-batch"),
        "gpu" | "gpu-batch" => return Err(Error::argument("--cull", "gpu culls for the raster kernel: use it with --engine gpu")),
        other => return Err(Error::argument("--cull", format!("'{other}' is not cpu, gpu or gpu-batch"))),
    };
    if args.walk_stats && kernel != Kernel::Compute {
        return Err(Error::argument("--walk-stats", "counts the compute kernel's walk: use it with --engine compute"));
    }
    let walk_stats = args.walk_stats;
    let options =
        CounterOptions { max_atlas: args.atlas, backend, limits, kernel, gpu_cull, batch_draw, walk_stats, ..args.pixels.options() };
    if backend == Backend::Noop {
        if args.check > 0 {
            return Err(Error::argument("--check", "the noop backend counts nothing to check: drop --check or use --backend platform"));
        }
        if options.accuracy.is_some() {
            return Err(Error::argument("--accuracy", "adaptive counting recounts by the counts, which the noop backend does not make"));
        }
    }
    Ok(options)
}

/// Times each model over its sampling plan's views on the GPU alone (`--engine gpu`); one JSON line
/// each. `startup` is what making `counter` took: with the other lanes' devices and the model's
/// upload it is reported as `gpu_startup_seconds`, as the hybrid engine reports its own.
fn bench_models(args: &BenchArgs, counter: &Counter, startup: f64, now: impl Fn() -> f64 + Copy) -> Result<()> {
    let (days, per_day, plan) = bench_plan(&args.samples)?;
    let lane_count = args.lanes.unwrap_or_else(|| default_lanes(counter.adapter_info()));
    if lane_count == 0 {
        return Err(Error::argument("--lanes", "must be at least 1"));
    }
    let lanes_made = now();
    let mut counters = vec![];
    for _ in 1..lane_count {
        counters.push(pollster::block_on(Counter::new(counter.options()))?);
    }
    let startup = startup + now() - lanes_made;
    let counters: Vec<&Counter> = std::iter::once(counter).chain(&counters).collect();
    for name in &args.models {
        let t0 = now();
        let (scene, location, shading) = bench_model(name, &args.location)?;
        let uploading = now();
        let gpus = counters.iter().map(|c| c.upload(&scene)).collect::<Result<Vec<_>>>()?;
        let upload_seconds = now() - uploading;
        let lanes: Vec<Lane<'_>> = counters.iter().zip(&gpus).map(|(counter, gpu)| Lane { counter, gpu }).collect();
        let load_seconds = now() - t0;
        let all = sunlit::year::annual::sample_requests(&scene, &location, plan)?;
        let spread;
        let requests = match args.views {
            Some(n) => {
                spread = bench::spread(&all, n);
                &spread
            }
            None => &all,
        };
        let t = pollster::block_on(bench::time_requests(&lanes, requests, now))?;
        let estimated = t.seconds * all.len() as f64 / t.views.max(1) as f64;
        let mut line = json!({
            "model": name,
            "engine": args.engine.kind()?.name(),
            "gpu_startup_seconds": startup + upload_seconds,
            "receivers": scene.receivers.len(),
            "shading_polygons": shading,
            "triangles": scene.triangle_count(),
            "samples": format!("{days}x{per_day}"),
            "resolution": counter.resolution(),
            "cull": match (counter.culls_on_gpu_for(&gpus[0]), counter.draws_by_batch_for(&gpus[0])) {
                (true, true) => "gpu-batch",
                (true, false) => "gpu",
                _ => "cpu",
            },
            "accuracy": counter.options().accuracy,
            "sides": t.sides,
            "lanes": lanes.len(),
            "views": all.len(),
            "views_timed": t.views,
            "views_rendered": t.rendered,
            "views_skipped": t.skipped,
            // Views in the tiles drawn: with the GPU's culling on noop every drawn view reads
            // back as unshaded and is not `rendered`, so the host's cost a view is a drawn one's.
            "views_drawn": t.drawn,
            "seconds": t.seconds,
            "estimated_seconds_all_views": estimated,
            "views_per_second": t.views_per_second,
            "planning_seconds": t.planning_seconds,
            "host_stages_seconds": t.host_stages,
            // The compute kernel's node pool (0 with the raster kernel) and the batches it made
            // count again by overflowing.
            "bin_pool_nodes": counters.iter().map(|c| c.bin_pool().0).max(),
            "bin_pool_reruns": counters.iter().map(|c| c.bin_pool().1).sum::<u64>(),
            // With --walk-stats: what the compute kernel's raster tiles walked, summed.
            "compute_walk": args.walk_stats.then(|| walk_totals(&counters)),
            // GPU-culled views whose shading the host tested (the GPU's test undecided, and the
            // render not fully lit), since the counters were made.
            "shading_tested_on_cpu": counters.iter().map(|c| c.shading_tested_on_cpu()).sum::<u64>(),
            // The compute kernel's views a submission (its batches are not the atlas's).
            "compute_views_per_submission": compute_views_per_submission(&counters),
            "seconds_per_rendered_view": t.seconds / t.rendered.max(1) as f64,
            "seconds_per_drawn_view": t.seconds / t.drawn.max(1) as f64,
            "mean_triangles_drawn": t.mean_triangles_drawn.round(),
            "tiles_rendered": t.tiles_rendered,
            "mean_triangles_per_tile": t.mean_triangles_per_tile.round(),
            "load_seconds": load_seconds,
            "peak_memory_mib": peak_memory_mib(),
        });
        if args.gpu_cull {
            let cull = pollster::block_on(bench::time_gpu_cull(counter, &gpus[0], requests, counter.resolution(), now))?;
            line["gpu_cull"] = json!(cull);
        }
        if args.check > 0 {
            let check = bench::check_exact(&scene, requests, &t.counted, args.check);
            line["exact_views_checked"] = json!(check.views);
            line["mean_abs_error"] = json!(check.mean);
            line["max_abs_error"] = json!(check.max);
            if counter.options().accuracy.is_some() {
                line["views_above_their_error_estimate"] = json!(check.above_estimate);
            }
        }
        println!("{line}");
    }
    Ok(())
}

/// A bench model: generated by name (with its own location and shading polygon count), else
/// read from a file at `location`. A name that is neither gets the list of generated names.
fn bench_model(name: &str, location: &str) -> Result<(Scene, Location, Option<usize>)> {
    let generated = bench::models::CATALOGUE.iter().any(|(n, _)| *n == name) || !std::path::Path::new(name).exists();
    if generated {
        let m = bench::models::generate(name)?;
        let scene = model::load_bytes(&[(format!("{name}.glb"), m.glb.to_glb())], &LoadOptions::default())?;
        return Ok((scene, m.location, Some(m.shading_polygons)));
    }
    Ok((model::load(&[PathBuf::from(name)], &LoadOptions::default())?, Location::parse(location)?, None))
}

/// `--sky`: each model's sky pass (the views `sunlit annual --summary` adds) timed on the chosen
/// engine, engine start-up apart; one JSON line a model.
fn bench_sky(args: &BenchArgs, scheme: &str) -> Result<()> {
    let patches = sunlit::sky::patches::SkyPatches::parse(scheme)?;
    let options = counter_options(args)?;
    if options.backend == Backend::Noop {
        return Err(Error::argument("--backend", "noop times the GPU counter's sun views alone, not a sky pass"));
    }
    for name in &args.models {
        let t0 = Instant::now();
        let (scene, _, shading) = bench_model(name, &args.location)?;
        let engine = HybridEngine::new(&scene, args.engine.kind()?, options, args.lanes, args.engine.source())?;
        let load_seconds = t0.elapsed().as_secs_f64();
        let mut views = 0;
        let start = Instant::now();
        let sky = pollster::block_on(sunlit::sky::views::sky_views(&engine, &scene, &patches, &mut |p: Progress| {
            views = p.total;
            Ok(())
        }))?;
        let sky_seconds = start.elapsed().as_secs_f64();
        let mean: f64 = (0..sky.receivers()).map(|r| sky.isotropic(r, 1.0)).sum::<f64>() / sky.receivers().max(1) as f64;
        let line = json!({
            "model": name,
            "engine": args.engine.kind()?.name(),
            "receivers": scene.receivers.len(),
            "shading_polygons": shading,
            "patches": patches.len(),
            "sky_views": views,
            "load_seconds": load_seconds,
            "sky_seconds": sky_seconds,
            "mean_sky_view_factor": mean,
        });
        println!("{line}");
    }
    Ok(())
}

/// The sampling plan `--samples` names.
fn bench_plan(samples: &str) -> Result<(usize, usize, SamplingPlan)> {
    let (days, per_day) = samples
        .split_once(['x', 'X'])
        .and_then(|(d, s)| Some((d.trim().parse().ok()?, s.trim().parse().ok()?)))
        .ok_or_else(|| Error::argument("--samples", format!("'{samples}' is not DAYSxPER_DAY (e.g. 27x19)")))?;
    Ok((days, per_day, SamplingPlan::new(days, per_day)?))
}

/// [`bench_models`] with `--engine auto` or `exact`: times the hybrid engine over each model's
/// views (calibration and GPU start-up included, and reported apart); `--check` compares the
/// GPU-routed views, and as many exactly-clipped ones, with the exact reference.
fn bench_hybrid(args: &BenchArgs, now: impl Fn() -> f64 + Copy) -> Result<()> {
    let (days, per_day, plan) = bench_plan(&args.samples)?;
    let kind = args.engine.kind()?;
    let options = counter_options(args)?;
    for name in &args.models {
        let t0 = now();
        let (scene, location, shading) = bench_model(name, &args.location)?;
        let engine = HybridEngine::new(&scene, kind, options, args.lanes, args.engine.source())?;
        let load_seconds = now() - t0;
        let all = sunlit::year::annual::sample_requests(&scene, &location, plan)?;
        let requests = match args.views {
            Some(n) => bench::spread(&all, n),
            None => all.clone(),
        };
        // Routed as the whole plan would be: the GPU's start-up is weighed against all its views.
        engine.expect(all.len());
        let t1 = now();
        let answers = pollster::block_on(engine.answer(&requests))?;
        let seconds = now() - t1;
        let stats = engine.stats();
        // Once-a-run costs are not scaled with the views; they are reported apart.
        let once = stats.calibration_seconds + stats.gpu_startup_seconds;
        let estimated = (seconds - once).max(0.0) * all.len() as f64 / requests.len().max(1) as f64;
        let rendered = answers.iter().filter(|a| a.side.is_some()).count();
        let mut sides: std::collections::BTreeMap<u32, usize> = Default::default();
        answers.iter().filter_map(|a| a.side).for_each(|s| *sides.entry(s).or_default() += 1);
        let mut line = json!({
            "model": name,
            "engine": kind.name(),
            "receivers": scene.receivers.len(),
            "shading_polygons": shading,
            "triangles": scene.triangle_count(),
            "samples": format!("{days}x{per_day}"),
            "resolution": options.resolution,
            "accuracy": options.accuracy,
            "sides": sides,
            "lanes": engine.lanes().map_or(0, |l| l.len()),
            "views": all.len(),
            "views_timed": requests.len(),
            "views_rendered": rendered,
            "views_skipped": requests.len() - rendered,
            "seconds": seconds,
            "estimated_seconds_all_views": estimated,
            "views_per_second": requests.len() as f64 / seconds.max(1e-9),
            "exact_views": stats.exact_views,
            "gpu_views": stats.gpu_views,
            "exact_seconds": stats.exact_seconds,
            "gpu_seconds": stats.gpu_seconds,
            "calibration_seconds": stats.calibration_seconds,
            "gpu_startup_seconds": stats.gpu_startup_seconds,
            "convex_objects": engine.exact().map(|e| e.convex_objects()),
            "calibration": engine.profile().map(|(p, from)| json!({"from": from, "profile": p})),
            "load_seconds": load_seconds,
            "peak_memory_mib": peak_memory_mib(),
        });
        if args.check > 0 {
            let (gpu_check, exact_check) = bench::check_answers(&scene, &requests, &answers, args.check);
            line["exact_views_checked"] = json!(gpu_check.views);
            line["mean_abs_error"] = json!(gpu_check.mean);
            line["max_abs_error"] = json!(gpu_check.max);
            line["exact_engine_views_checked"] = json!(exact_check.views);
            line["exact_engine_max_abs_difference"] = json!(exact_check.max);
        }
        println!("{line}");
    }
    Ok(())
}

/// Peak resident memory of this process (VmHWM), where the OS reports it.
pub(crate) fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kib: f64 = status.lines().find_map(|l| l.strip_prefix("VmHWM:"))?.trim().trim_end_matches("kB").trim().parse().ok()?;
    Some(kib / 1024.0)
}

/// The compute kernel's views counted per batch (one submission each, reruns aside), over
/// `counters`; `None` where no batch was counted by it.
fn compute_views_per_submission(counters: &[&Counter]) -> Option<f64> {
    let (batches, views) = counters.iter().map(|c| c.compute_batches()).fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    (batches > 0).then(|| views as f64 / batches as f64)
}

/// The compute kernel's raster walk over `counters`, summed, with the means a tile.
fn walk_totals(counters: &[&Counter]) -> serde_json::Value {
    let mut sum = sunlit::count::gpu::compute::WalkStats::default();
    for counter in counters {
        sum += counter.walk_stats();
    }
    let per_tile = |n: u64| n as f64 / sum.tiles.max(1) as f64;
    json!({
        "totals": sum,
        "entries_per_tile": per_tile(sum.entries),
        "set_up_per_tile": per_tile(sum.set_up),
        "rows_per_tile": per_tile(sum.rows),
        "pixels_per_tile": per_tile(sum.pixels),
    })
}
