//! `sunlit district`, the CLI's edge of [`sunlit::sweep::district`]: its flags, the arguments that
//! define a run (its fingerprint, and what each tile's child process and Slurm task is given),
//! and the three ways to run: every unfinished tile here (`--jobs` child processes), one tile
//! (`--index`, what a child or a Slurm task runs), or a Slurm job array with a merge job.

use sunlit::count::gpu::CounterOptions;
use sunlit::model::cityjson::CitySource;
use sunlit::sky::patches::SkyPatches;
use sunlit::sun::weather::Weather;
use sunlit::sweep::district::{self, TileCount, TileDone, TileSettings, Tiling};
use sunlit::sweep::{record, run, slurm};

use super::*;

#[derive(Args)]
pub(super) struct DistrictArgs {
    /// The city model: CityJSON 1.1/2.0 (.city.json) or CityJSONSeq (.city.jsonl).
    #[arg(value_name = "CITY")]
    city: PathBuf,
    /// Output folder: cadastre.city.json, cadastre.csv, cadastre-roofs.geojson, failed.csv, and
    /// the records of finished tiles (.done/), so a second run counts only what is missing.
    #[arg(short = 'o', long = "output", value_name = "DIR")]
    output: PathBuf,
    /// Weather file (EPW): location, and the irradiation.
    #[arg(long, value_name = "FILE")]
    epw: PathBuf,
    /// Tile side in metres: a building belongs to the tile holding its footprint centroid.
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    tile: f64,
    /// Context radius in metres: a tile is counted with every surface within it (docs/district.md
    /// gives the radius that holds every shadow).
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    context: f64,
    /// Receivers: glob over surface names (OBJECT_ID/TYPE/INDEX) or semantic types
    /// ('RoofSurface'); repeatable. Default: roofs and walls.
    #[arg(long = "receivers", value_name = "GLOB")]
    receivers: Vec<String>,
    /// Only these buildings' surfaces receive (ids, comma-separated).
    #[arg(long, value_name = "ID,...")]
    buildings: Option<String>,
    /// Receivers by attribute, KEY=VALUE (also !=, <, <=, >, >=): the surface's semantic
    /// surface's attributes, else its CityObject's, else its parents'. Numbers compare as numbers
    /// (storeysAboveGround>=3); text as a case-insensitive glob (function=resid*). Repeatable: a
    /// receiver meets every rule, beside --receivers and --buildings.
    #[arg(long = "where", value_name = "KEY=VALUE")]
    where_rules: Vec<String>,
    /// Level of detail read (2.2, or 2 for any 2.x); default: each object's highest.
    #[arg(long, value_name = "LOD")]
    lod: Option<String>,
    /// Degrees clockwise from true north of the model's grid north (+y); default: grid north is
    /// true north.
    #[arg(long, value_name = "DEG", default_value_t = 0.0, allow_negative_numbers = true)]
    north: f64,
    /// Timesteps per hour.
    #[arg(long, value_name = "N", default_value_t = 1)]
    timesteps_per_hour: u32,
    /// Sampled days, evenly over the year.
    #[arg(long, value_name = "N", default_value_t = SamplingPlan::default().days)]
    days_per_year: usize,
    /// Samples per day and lit period of each surface.
    #[arg(long, value_name = "N", default_value_t = SamplingPlan::default().per_day)]
    samples_per_day: usize,
    /// auto, gpu or exact (see `annual --engine`).
    #[arg(long, value_name = "auto|gpu|exact", default_value = "auto")]
    engine: String,
    /// GPU tile side in pixels.
    #[arg(long, value_name = "PIXELS", default_value_t = 512)]
    resolution: u32,
    /// Ground reflectance (0..1); default: the EPW's albedo.
    #[arg(long, value_name = "R")]
    albedo: Option<f64>,
    /// Sky patches: tregenza or reinhart:N.
    #[arg(long, value_name = "SCHEME", default_value = "tregenza")]
    sky_patches: String,
    /// Per-point maps on roofs: a grid of points M metres apart on every roof, each point's year
    /// in cadastre-points.csv and .geojson.
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    grid: Option<f64>,
    /// With --grid: each roof's usable area, where a point's total irradiation is at least this
    /// many kWh/m² (usable_area_m2 in the CSV, GeoJSON and CityJSON).
    #[arg(long, value_name = "KWH", requires = "grid", allow_negative_numbers = true)]
    min_kwh_m2: Option<f64>,
    /// With --grid: what PV tools read for the roofs' points, each tile's in pv/ and every
    /// point's in cadastre-points-pvlib.csv (pvlib) and cadastre-points-sam.json (SAM pvsamv1).
    #[arg(long, requires = "grid")]
    pv: bool,
    /// Also each receiver's whole-year table of sunlit fractions, the CSV `sunlit annual CITY -o
    /// FILE.csv` writes for the same receivers: cadastre-year.csv (each tile's in year/). Without
    /// it a tile keeps annual sums only.
    #[arg(long)]
    year_table: bool,
    /// Tiles counted side by side, each a child process.
    #[arg(long, value_name = "N", default_value_t = 1)]
    jobs: usize,
    /// Receivers whose year a tile counts at once (default 128): a tile's peak memory follows
    /// it; the answers are the same bit for bit.
    #[arg(long, value_name = "N")]
    receiver_batch: Option<usize>,
    /// Submit a Slurm job array (a task per unfinished tile) and a merge job instead.
    #[arg(long, conflicts_with_all = ["index", "merge"])]
    slurm: bool,
    /// With --slurm: further sbatch options for both jobs, split at spaces.
    #[arg(long, value_name = "ARGS", requires = "slurm", allow_hyphen_values = true)]
    sbatch: Option<String>,
    /// Count only tile INDEX (what a child process or Slurm task runs); no merge.
    #[arg(long, value_name = "INDEX", conflicts_with = "merge")]
    index: Option<usize>,
    /// Only merge the finished tiles into the cadastre (exit 1 when one is unfinished).
    #[arg(long)]
    merge: bool,
}

impl DistrictArgs {
    /// The arguments that define the result (not where or how it runs), paths absolute: the
    /// fingerprint, and what every child and task is given before `-o DIR`.
    fn defining(&self, city: &std::path::Path, epw: &std::path::Path) -> Vec<String> {
        let mut words = vec![
            city.display().to_string(),
            "--epw".into(),
            epw.display().to_string(),
            "--tile".into(),
            self.tile.to_string(),
            "--context".into(),
            self.context.to_string(),
            "--north".into(),
            self.north.to_string(),
            "--timesteps-per-hour".into(),
            self.timesteps_per_hour.to_string(),
            "--days-per-year".into(),
            self.days_per_year.to_string(),
            "--samples-per-day".into(),
            self.samples_per_day.to_string(),
            "--engine".into(),
            self.engine.clone(),
            "--resolution".into(),
            self.resolution.to_string(),
            "--sky-patches".into(),
            self.sky_patches.clone(),
        ];
        for r in &self.receivers {
            words.extend(["--receivers".into(), r.clone()]);
        }
        for w in &self.where_rules {
            words.extend(["--where".into(), w.clone()]);
        }
        let optional = [
            ("--buildings", self.buildings.clone()),
            ("--lod", self.lod.clone()),
            ("--albedo", self.albedo.map(|a| a.to_string())),
            ("--grid", self.grid.map(|g| g.to_string())),
            ("--min-kwh-m2", self.min_kwh_m2.map(|m| m.to_string())),
            // Not the result, but every tile and task is given it, as the rest.
            ("--receiver-batch", self.receiver_batch.map(|b| b.to_string())),
        ];
        for (flag, value) in optional {
            if let Some(v) = value {
                words.extend([flag.to_string(), v]);
            }
        }
        if self.pv {
            words.push("--pv".into());
        }
        if self.year_table {
            words.push("--year-table".into());
        }
        words
    }

    fn load(&self) -> LoadOptions {
        let buildings =
            self.buildings.as_deref().unwrap_or("").split(',').map(str::trim).filter(|b| !b.is_empty()).map(String::from).collect();
        LoadOptions {
            receivers: self.receivers.clone(),
            north: self.north,
            buildings,
            lod: self.lod.clone(),
            attribute_rules: self.where_rules.clone(),
            ..Default::default()
        }
    }
}

pub(super) fn district(args: DistrictArgs) -> Result<()> {
    let io = |source: std::io::Error, path: &std::path::Path| Error::Io { path: path.to_path_buf(), source };
    let dir = std::path::absolute(&args.output).map_err(|e| io(e, &args.output))?;
    let city_path = std::path::absolute(&args.city).map_err(|e| io(e, &args.city))?;
    let epw_path = std::path::absolute(&args.epw).map_err(|e| io(e, &args.epw))?;
    if args.jobs == 0 {
        return Err(Error::argument("jobs", "must be at least 1"));
    }
    if args.receiver_batch == Some(0) {
        return Err(Error::argument("receiver-batch", "must be at least 1"));
    }
    // Everything that can be refused is refused before a tile is counted.
    let settings = AnnualSettings {
        epw_file: Some(epw_path.clone()),
        timesteps_per_hour: Some(args.timesteps_per_hour),
        days_per_year: Some(args.days_per_year),
        samples_per_day: Some(args.samples_per_day),
        ..Default::default()
    }
    .resolve()?;
    let engine = EngineKind::parse(&args.engine)
        .map_err(|_| Error::argument("--engine", format!("'{}' is not one of auto, gpu, exact", args.engine)))?;
    let patches = SkyPatches::parse(&args.sky_patches)?;
    let grid = args.grid.map(|g| district::RoofGrid::new(g, args.min_kwh_m2)).transpose()?;
    let weather = Weather::from_epw(&epw_path)?;
    let weather = match args.albedo {
        Some(a) => weather.with_albedo(a)?,
        None => weather,
    };
    let bytes = std::fs::read(&city_path).map_err(|e| io(e, &city_path))?;
    let name = args.city.display().to_string();
    let lod = args.lod.as_deref();
    // The file is parsed once (a CityJSONSeq's feature lines as each pass reads them): the plan
    // pass holds no surfaces, a tile then builds only its part, the merge only what it writes.
    let source = CitySource::parse(&name, &bytes)?;
    let load = args.load();
    let mut receivers = model::CityReceivers::new(&load)?;
    let plan = district::CityPlan::of_source_seeing(&name, &source, lod, args.north, &mut |s| receivers.see(s))?;
    let tiling = district::tiles_of(&plan, args.tile, args.context)?;
    plan.check_buildings(&load.buildings)?;
    receivers.check()?;
    let tile_city = args.index.map(|k| district::read_tile_city(&name, &source, lod, &plan, &tiling, k)).transpose()?;
    drop(plan);
    let defining = args.defining(&city_path, &epw_path);
    let fingerprint = district::fingerprint(&defining, &city_path);
    let north = model::city_north_note(args.north);
    record::prepare(&dir)?;
    let exe = std::env::current_exe().map_err(|e| io(e, std::path::Path::new("sunlit")))?;
    let sunlit_district = |more: &[String]| -> Vec<String> {
        let mut words = vec![exe.display().to_string(), "district".into()];
        words.extend(defining.iter().cloned());
        words.extend(["-o".into(), dir.display().to_string()]);
        words.extend(more.iter().cloned());
        words
    };
    if let (Some(k), Some(city)) = (args.index, tile_city) {
        // The tile counts with its part alone.
        drop(source);
        let tile = TileSettings {
            load: args.load(),
            settings: &settings,
            weather: &weather,
            patches: &patches,
            engine,
            counter: CounterOptions { resolution: args.resolution, ..Default::default() },
            lanes: None,
            grid,
            pv: args.pv,
            batch: args.receiver_batch.unwrap_or(district::RECEIVER_BATCH),
            year_table: args.year_table.then(|| dir.clone()),
        };
        return count_one(&dir, &city, &tiling, k, &tile, &fingerprint);
    }
    if args.merge {
        return merge(&dir, source, &name, lod, &tiling, &fingerprint, &north);
    }
    let pending = district::pending(&dir, &tiling, &fingerprint);
    eprintln!(
        "{} tiles of {} m with {} m of context ({} buildings); {} to count; {north}",
        tiling.tiles.len(),
        args.tile,
        args.context,
        tiling.tiles.iter().map(|t| t.buildings.len()).sum::<usize>(),
        pending.len()
    );
    if args.slurm {
        if pending.is_empty() {
            return merge(&dir, source, &name, lod, &tiling, &fingerprint, &north);
        }
        let options = slurm::SlurmOptions {
            dir: dir.clone(),
            task_command: sunlit_district(&["--index".into()]),
            merge_command: sunlit_district(&["--merge".into()]),
            array_max: None,
            sbatch: args.sbatch.as_deref().unwrap_or("").split_whitespace().map(String::from).collect(),
        };
        let s = slurm::submit(&options, &pending)?;
        println!("array job {}: tiles {}", s.array, slurm::array_list(&s.tasks));
        println!("merge job {}: after job {} ends, writes {}", s.merge, s.array, dir.join(district::CADASTRE_CITYJSON).display());
        return Ok(());
    }
    run_local(&exe, &dir, &pending, args.jobs, &|k| sunlit_district(&["--index".into(), k.to_string()]))?;
    merge(&dir, source, &name, lod, &tiling, &fingerprint, &north)
}

/// Counts tile `k` here and records it (or its failure).
fn count_one(
    dir: &std::path::Path,
    city: &sunlit::model::cityjson::City,
    tiling: &Tiling,
    k: usize,
    tile: &TileSettings,
    fingerprint: &sunlit::sweep::record::Fingerprint,
) -> Result<()> {
    let start = Instant::now();
    let log = record::log_path(dir, &district::tile_id(k));
    let counted =
        district::count_tile(city, tiling, k, tile, &mut |_| Ok(())).and_then(|TileCount { rows, points, pv, year, casters, stages }| {
            let seconds = start.elapsed().as_secs_f64();
            eprintln!("tile {k}: {} surfaces, {} points against {casters} in {seconds:.1} s", rows.len(), points.len());
            eprintln!("tile {k} stages: {}", stages.line());
            let peak_mib = crate::bench_cli::peak_memory_mib();
            if let Some(peak) = peak_mib {
                eprintln!("tile {k}: peak resident memory {peak:.1} MiB");
            }
            let written = Instant::now();
            // The PV files before the record: a finished tile has them.
            if let Some(pv) = &pv {
                sunlit::sweep::district_pv::write_tile_pv(dir, k, pv)?;
            }
            let pv = pv.map(|p| p.sums);
            let stages = Some(stages);
            district::write_tile(
                dir,
                &TileDone { tile: k, fingerprint: fingerprint.clone(), seconds, casters, rows, points, pv, year, stages, peak_mib },
            )?;
            eprintln!("tile {k}: record written in {:.1} s", written.elapsed().as_secs_f64());
            Ok(())
        });
    if let Err(e) = &counted {
        let _ = district::write_tile_failure(dir, k, Some(1), &e.render(&flag), &log);
    }
    counted
}

/// Runs each pending tile as a child process, `jobs` at a time; a failed tile is recorded and
/// the others go on.
fn run_local(
    exe: &std::path::Path,
    dir: &std::path::Path,
    pending: &[usize],
    jobs: usize,
    command: &(dyn Fn(usize) -> Vec<String> + Sync),
) -> Result<()> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let worker = || {
        loop {
            let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            let Some(&k) = pending.get(i) else { break };
            let log = record::log_path(dir, &district::tile_id(k));
            // The child's words start with the program itself.
            let words = command(k);
            let status = run::spawn_sunlit(exe, &words[1..], &log);
            match status {
                Ok(s) if s.success() => eprintln!("[{}/{}] tile {k}: counted", i + 1, pending.len()),
                Ok(s) => {
                    let reason = run::last_error(&log, s);
                    eprintln!("[{}/{}] tile {k}: FAILED: {reason}", i + 1, pending.len());
                    let _ = district::write_tile_failure(dir, k, s.code(), &reason, &log);
                }
                Err(e) => {
                    let _ = district::write_tile_failure(dir, k, None, &e.to_string(), &log);
                }
            }
        }
    };
    std::thread::scope(|s| {
        for _ in 0..jobs.min(pending.len().max(1)) {
            s.spawn(worker);
        }
    });
    Ok(())
}

/// Merges the finished tiles; fails listing the unfinished ones.
fn merge(
    dir: &std::path::Path,
    source: CitySource,
    file: &str,
    lod: Option<&str>,
    tiling: &Tiling,
    fingerprint: &sunlit::sweep::record::Fingerprint,
    north: &str,
) -> Result<()> {
    let merged = district::merge(dir, source, file, lod, tiling, fingerprint, north)?;
    if merged.unfinished.is_empty() {
        for path in &merged.written {
            eprintln!("wrote {}", path.display());
        }
        eprintln!("{} surfaces; {north}", merged.surfaces);
        return Ok(());
    }
    let list: Vec<String> = merged
        .unfinished
        .iter()
        .map(|(id, code, reason)| format!("{id} (exit {}): {reason}", code.map_or("-".into(), |c| c.to_string())))
        .collect();
    Err(Error::argument(
        "district",
        format!(
            "{} tile(s) unfinished (listed in {}; run again to count only them):\n  {}",
            list.len(),
            dir.join(sunlit::sweep::FAILED_CSV).display(),
            list.join("\n  ")
        ),
    ))
}
