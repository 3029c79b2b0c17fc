//! `sunlit`, the command line: a thin edge over the library.
//!
//! Owns the flags: clap parses them, they become the library's settings
//! ([`sunlit::year::settings::AnnualSettings`], resolved there as the web's are), and a library
//! error's parameter names become the flags that set them when it is printed ([`flags::FLAGS`]).
//!
//! Each subcommand is its argument struct and a short translation into library calls; no logic of
//! the pipeline lives here. `sweep`, which also checks manifest lines as `annual` would, is in
//! `src/cli/sweep.rs`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::{Args, Parser, Subcommand};
use serde_json::json;

use sunlit::count::exact::Exact;
use sunlit::count::gpu::{Backend, Counter, CounterOptions, Kernel, LimitsProfile};
use sunlit::count::hybrid::{EngineKind, HybridEngine, ProfileSource};
use sunlit::count::lanes::{Lane, default_lanes};
use sunlit::count::{Engine, ViewAnswer, ViewRequest, leaf_fraction};
use sunlit::export::hook::{Hook, HookPlan};
use sunlit::model::calendar::WeatherDays;
use sunlit::model::obj::{ObjUnit, ObjUp};
use sunlit::model::{self, LoadOptions};
use sunlit::scene::Scene;
use sunlit::sun::SunPosition;
use sunlit::sun::location::Location;
use sunlit::year::annual::{AnnualOptions, Progress};
use sunlit::year::samples::{SamplingPlan, Timesteps};
use sunlit::year::settings::AnnualSettings;
use sunlit::year::settings::Resolved;
use sunlit::year::transmitting::VaryingShades;
use sunlit::{Error, Result, bench};

#[path = "cli/sweep.rs"]
mod sweep_cli;
use sweep_cli::{SweepArgs, sweep};
#[path = "cli/solar.rs"]
mod solar_cli;
use solar_cli::{solar_outputs, solar_plan};
#[path = "cli/interior_beam.rs"]
mod interior_beam_cli;
use interior_beam_cli::{beam_outputs, beam_plan};
#[path = "cli/bench.rs"]
mod bench_cli;
use bench_cli::{BenchArgs, run_bench};
#[path = "cli/district.rs"]
mod district_cli;
#[cfg(test)]
#[path = "cli/docs_check.rs"]
mod docs_check;
use district_cli::{DistrictArgs, district};
#[path = "cli/flags.rs"]
mod flags;
#[path = "cli/map.rs"]
mod map_cli;
#[path = "cli/progress.rs"]
mod progress;
use flags::flag;
use map_cli::{MapArgs, map};

#[derive(Parser)]
#[command(name = "sunlit", version, about = "Sunlit fractions of building surfaces, by GPU pixel counting or exact polygon clipping")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// Parsed once per run and matched at once, so the variants' sizes cost nothing worth boxing.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
enum Command {
    /// Sunlit fraction (sunlit area / area) of every receiver for one sun position.
    Fraction(FractionArgs),
    /// List the receivers (name, area, normal) and triangle counts a model gives; nothing is counted.
    Info(InfoArgs),
    /// Sunlit fractions at every EnergyPlus timestep of a year, written as the CSV EnergyPlus reads
    /// (and, with --idf-out, a copy of an EnergyPlus model that uses it).
    Annual(AnnualArgs),
    /// Time generated benchmark models (see --list) or model files over the views of an annual
    /// sampling plan, one JSON line a model (fields in docs/benchmarks.md); without models, views
    /// per second on synthetic occluder clouds and the office.
    Bench(BenchArgs),
    /// Many annual runs from a manifest (one JSON object a line: "id" plus annual's long
    /// options), counted here side by side or submitted as a Slurm job array; resumable.
    Sweep(SweepArgs),
    /// Per point: sun hours and direct irradiation over a period, or lit at an instant, on a grid
    /// or given points; sun-hours studies (bre-ground, en17037). See docs/maps.md.
    Map(MapArgs),
    /// A solar cadastre of a city model (CityJSON): its receivers in square tiles, each counted
    /// with the casters within a context radius, here or as a Slurm job array, merged into
    /// DIR/cadastre.city.json, cadastre.csv and cadastre-roofs.geojson. See docs/district.md.
    District(DistrictArgs),
}

#[derive(Args)]
struct AnnualArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Weather file (EPW) whose LOCATION line gives latitude, longitude and time zone; with
    /// --summary its direct normal irradiance also gives annual irradiation.
    /// Without --epw or --location, an EnergyPlus model's own Site:Location is used.
    #[arg(long, value_name = "FILE", conflicts_with = "location")]
    epw: Option<PathBuf>,
    /// Latitude (° north), longitude (° east), time zone (hours from UTC).
    #[arg(long, value_name = "LAT,LON,TZ", allow_hyphen_values = true)]
    location: Option<String>,
    /// Timesteps per hour (one EnergyPlus accepts: 1 2 3 4 5 6 10 12 15 20 30 60); default: the
    /// EnergyPlus model's Timestep, else 4.
    #[arg(long, value_name = "N")]
    timesteps_per_hour: Option<u32>,
    /// The calendar year (a leap year gives 366 days, 8784 rows per timestep per hour); default:
    /// the EnergyPlus model's RunPeriod Begin Year, else the EPW's year if it has a Feb 29, else
    /// a non-leap year.
    #[arg(long)]
    year: Option<i32>,
    /// Sampled days, evenly over the year.
    #[arg(long, value_name = "N", default_value_t = SamplingPlan::default().days)]
    days_per_year: usize,
    /// Samples per day and lit period of each surface (Chebyshev nodes: closer together towards
    /// sunrise and sunset, where shadows move fastest).
    #[arg(long, value_name = "N", default_value_t = SamplingPlan::default().per_day)]
    samples_per_day: usize,
    #[command(flatten)]
    pixels: PixelArgs,
    /// Devices counting side by side, each with its own copy of the scene; default: 2 on a CPU
    /// rasterizer (lavapipe bins triangles on one thread a device) with 2 or more cores, else 1.
    #[arg(long, value_name = "N")]
    lanes: Option<usize>,
    #[command(flatten)]
    engine: EngineArgs,
    /// Count every sun-up timestep directly instead of interpolating (the reference; slow).
    #[arg(long)]
    dense: bool,
    /// Count a timestep directly where the samples around it differ by more than this (a shadow
    /// edge sweeping through); 1 interpolates everywhere.
    #[arg(long, value_name = "T", default_value_t = sunlit::year::annual::DEFAULT_REFINE)]
    refine: f64,
    /// Interpolate a timestep only where part of the surface is proved lit at its sun, and count
    /// it otherwise: no shadow passing wholly between samples is lost (slower; off by default).
    #[arg(long)]
    prove_never_dark: bool,
    /// With refinement on: let a dark proof combine casters (coplanar panels forming one convex
    /// polygon, halves of a cell each covered by its own caster, a facade clipped where it meets
    /// the surface's plane). Exact (no step proved dark is lit), and the values are those without
    /// it: only views go. Without the flag the year tries them on one cell in 16 and keeps them
    /// where they settle at least 4 steps a cell tried there (on a city; not on blaas-louvres).
    #[arg(long, value_name = "BOOL", num_args = 0..=1, require_equals = true, default_missing_value = "true", action = clap::ArgAction::Set)]
    many_casters: Option<bool>,
    /// With --many-casters: let a facade meeting a surface's plane at an inner corner prove it
    /// dark along their shared edge (no margin there). Exact with the exact engine; off by
    /// default until shown for the GPU engine.
    #[arg(long)]
    inner_corners: bool,
    /// Output CSV, EnergyPlus's eplusshading.csv layout (written atomically).
    #[arg(short = 'o', long = "output", value_name = "FILE.csv")]
    output: PathBuf,
    /// Also write a per-surface summary (JSON or CSV, by extension; written atomically): area,
    /// mean fraction over sun-up timesteps, sky view factor, EnergyPlus's diffuse shading ratios
    /// and, with --epw, annual irradiation (kWh/m²): direct, sky diffuse, ground-reflected, total
    /// and unshaded total (docs/sky.md).
    #[arg(long, value_name = "FILE.json|FILE.csv")]
    summary: Option<PathBuf>,
    /// Also write total incident solar (W/m², beam + sky + ground, shaded) per surface and
    /// timestep, in the schedule CSV's layout (needs --epw; written atomically).
    #[arg(long, value_name = "FILE.csv")]
    irradiance: Option<PathBuf>,
    /// Also write each receiver's beam shaded fraction per timestep on pvlib's time index
    /// (docs/district.md shows the pvlib code that reads it).
    #[arg(long, value_name = "FILE.csv")]
    pvlib: Option<PathBuf>,
    /// Also write SAM pvsamv1's shading inputs (subarray1_shading_*) for the receivers taken as
    /// one array, as JSON (needs --epw).
    #[arg(long, value_name = "FILE.json")]
    sam: Option<PathBuf>,
    /// Ground reflectance (0..1) for every hour; default: the EPW's albedo (field 33), 0.2 where
    /// it is missing.
    #[arg(long, value_name = "R")]
    albedo: Option<f64>,
    /// Sky patches for the sky views: tregenza (145, the default) or reinhart:N (N = 1..6,
    /// 144·N² + 1 patches).
    #[arg(long, value_name = "SCHEME")]
    sky_patches: Option<String>,
    /// The sky that weighs the patches, with --epw: energyplus (EnergyPlus's Perez 1990
    /// irradiance model, the default), perez-all-weather (Radiance's gendaymtx sky, as Ladybug
    /// uses), cie-overcast or uniform (docs/sky-truth.md).
    #[arg(long, value_name = "NAME")]
    sky_model: Option<String>,
    /// Also write a copy of the EnergyPlus model given (IDF or epJSON, as given) that reads the
    /// CSV (by its absolute path); needs an .idf or .epJSON among the models.
    #[arg(long, value_name = "FILE")]
    idf_out: Option<PathBuf>,
    /// How the copy reads the CSV: scheduled (a Schedule:File per surface; what EnergyPlus 25.2
    /// uses) or imported (Schedule:File:Shading, which 25.2 ignores: every surface gets 1.0);
    /// default scheduled (a model before Version 9.3 cannot be hooked).
    #[arg(long, value_name = "FORM")]
    hook: Option<String>,
    /// With --idf-out (scheduled) and --epw: also hand EnergyPlus the beam through each exterior
    /// window onto its zone's inside faces, per timestep, as SurfaceProperty:SolarIncidentInside
    /// schedules read from OUTPUT with .interior-beam.csv for .csv (what the Scheduled method
    /// loses under FullInteriorAndExterior; see docs/energyplus-fidelity.md).
    #[arg(long)]
    interior_beam: bool,
    /// With --interior-beam: the solar transmittance (0..1) of windows whose construction gives
    /// none sunlit reads (one simple glazing layer or one spectral-average pane).
    #[arg(long, value_name = "T", requires = "interior_beam")]
    glass_transmittance: Option<f64>,
    /// With --interior-beam: the solar transmittance by angle of incidence of windows whose
    /// construction sunlit cannot read, ANGLE:T pairs from 0° (degrees, never rising), e.g.
    /// 0:0.6,40:0.58,60:0.5,80:0.25 (as `map --inside --glass-curve`); it takes precedence over
    /// --glass-transmittance, which then only the visible light would use (the beam has none).
    #[arg(long, value_name = "ANGLE:T,...", requires = "interior_beam")]
    glass_curve: Option<String>,
    /// Foliage keeps its leaves all year.
    #[arg(long, conflicts_with_all = ["leaf_out", "leaf_fall"])]
    evergreen: bool,
    /// Leaf-out period, first and last day (MM-DD or day of year); default 04-15,05-31, half a
    /// year later south of the equator.
    #[arg(long, value_name = "START,END", requires = "leaf_fall")]
    leaf_out: Option<String>,
    /// Leaf-fall period (MM-DD or day of year); default 10-01,11-15, half a year later south of
    /// the equator.
    #[arg(long, value_name = "START,END", requires = "leaf_out")]
    leaf_fall: Option<String>,
}

impl AnnualArgs {
    /// The flags as the library's settings (resolved there, as the web's are).
    fn settings(&self) -> Result<AnnualSettings> {
        let coordinates = self.location.as_deref().map(Location::parse).transpose()?;
        Ok(AnnualSettings {
            latitude: coordinates.as_ref().map(|l| l.latitude),
            longitude: coordinates.as_ref().map(|l| l.longitude),
            time_zone: coordinates.as_ref().map(|l| l.time_zone),
            epw_file: self.epw.clone(),
            timesteps_per_hour: self.timesteps_per_hour,
            days_per_year: Some(self.days_per_year),
            samples_per_day: Some(self.samples_per_day),
            refine: Some(self.refine),
            prove_never_dark: Some(self.prove_never_dark),
            many_casters: self.many_casters,
            inner_corners: Some(self.inner_corners),
            dense: Some(self.dense),
            evergreen: Some(self.evergreen),
            leaf_out: self.leaf_out.clone(),
            leaf_fall: self.leaf_fall.clone(),
            sky_model: self.sky_model.clone(),
            ..Default::default()
        })
    }
}

#[derive(Args, Clone)]
struct ModelArgs {
    /// Model files, all casting shadows: glTF (.glb, .gltf), CityJSON (.city.json, .city.jsonl),
    /// OBJ (.obj) and at most one EnergyPlus model (.idf, .epJSON), whose outdoor surfaces and
    /// windows are the receivers; other files beside an EnergyPlus model are context (they only
    /// cast shadows).
    #[arg(required = true, value_name = "MODEL")]
    models: Vec<PathBuf>,
    /// Receivers: glob over node names (EnergyPlus: surface names; CityJSON: OBJECT_ID/TYPE/INDEX
    /// or the semantic type, e.g. RoofSurface; OBJ: groups and objects), case-insensitive;
    /// repeatable. Default: the nodes marked {"sunlit": {"receiver": true}} in glTF extras, and
    /// CityJSON roofs and walls, else every named mesh node; an EnergyPlus model's outdoor surfaces
    /// and windows.
    #[arg(long = "receivers", value_name = "GLOB")]
    receivers: Vec<String>,
    /// Degrees clockwise from true north of a glTF model's north (its −Z), as EnergyPlus's
    /// Building North Axis; an EnergyPlus model's own North Axis is read from it instead.
    #[arg(long, value_name = "DEG", default_value_t = 0.0, allow_negative_numbers = true)]
    north: f64,
    /// Foliage (deciduous unless --evergreen): glob over node names; each leaf (a connected group
    /// of the node's triangles) casts a shadow only while in leaf (--leaf-out, --leaf-fall). Repeatable.
    #[arg(long = "foliage", value_name = "GLOB")]
    foliage: Vec<String>,
    /// See-through nodes (e.g. perforated screens): GLOB=T lets T (0..1) of the beam through. Repeatable.
    #[arg(long = "transmittance", value_name = "GLOB=T")]
    transmittance: Vec<String>,
    /// CityJSON: only these buildings' surfaces receive (Building or BuildingPart ids, comma-separated).
    #[arg(long, value_name = "ID,...")]
    buildings: Option<String>,
    /// CityJSON: receivers by attribute, KEY=VALUE (also !=, <, <=, >, >=): the surface's semantic
    /// surface's attributes, else its CityObject's, else its parents'. Numbers compare as numbers
    /// (storeysAboveGround>=3); text as a case-insensitive glob (function=resid*). Repeatable: a
    /// receiver meets every rule, beside --receivers and --buildings.
    #[arg(long = "where", value_name = "KEY=VALUE")]
    where_rules: Vec<String>,
    /// CityJSON: the level of detail read (2.2, or 2 for any 2.x); default: each object's highest.
    #[arg(long, value_name = "LOD")]
    lod: Option<String>,
    /// OBJ: the up axis, y (default) or z.
    #[arg(long, value_name = "y|z")]
    up: Option<String>,
    /// OBJ: the unit of its coordinates: m (default), cm, mm, ft, in.
    #[arg(long, value_name = "UNIT")]
    unit: Option<String>,
}

impl ModelArgs {
    fn options(&self) -> LoadOptions {
        LoadOptions {
            receivers: self.receivers.clone(),
            north: self.north,
            foliage: self.foliage.clone(),
            transmittance: self.transmittance.iter().map(|t| model::parse_transmittance(t)).collect::<Result<_>>().unwrap_or_default(),
            buildings: self
                .buildings
                .as_deref()
                .unwrap_or("")
                .split(',')
                .map(str::trim)
                .filter(|b| !b.is_empty())
                .map(String::from)
                .collect(),
            lod: self.lod.clone(),
            attribute_rules: self.where_rules.clone(),
            up: self.up.as_deref().map(ObjUp::parse).transpose().unwrap_or_default().unwrap_or_default(),
            unit: self.unit.as_deref().map(ObjUnit::parse).transpose().unwrap_or_default().unwrap_or_default(),
            ..Default::default()
        }
    }

    /// Refuses a malformed `--transmittance`, `--up` or `--unit` before anything is read.
    fn check(&self) -> Result<()> {
        self.up.as_deref().map(ObjUp::parse).transpose()?;
        self.unit.as_deref().map(ObjUnit::parse).transpose()?;
        self.transmittance.iter().try_for_each(|t| model::parse_transmittance(t).map(drop))
    }

    fn load(&self) -> Result<Scene> {
        self.check()?;
        model::load(&self.models, &self.options())
    }

    fn load_all(&self, all_energyplus_surfaces: bool) -> Result<model::Loaded> {
        self.check()?;
        model::load_all(&self.models, &LoadOptions { all_energyplus_surfaces, ..self.options() })
    }

    /// The scene with mesh nodes picked as rooms (`interior`) and glass (`glazing`).
    fn load_rooms(&self, interior: &[String], glazing: &[String]) -> Result<model::Loaded> {
        self.check()?;
        model::load_all(&self.models, &LoadOptions { interior: interior.to_vec(), glazing: glazing.to_vec(), ..self.options() })
    }

    /// The scene with EnergyPlus shades at the given transmittances.
    fn load_with_shades(&self, shade_transmittance: Vec<(String, f64)>) -> Result<Scene> {
        model::load(&self.models, &LoadOptions { shade_transmittance, ..self.options() })
    }
}

/// How views are counted: the tile side, or a target error (fraction, annual, bench).
#[derive(Args)]
struct PixelArgs {
    /// Side in pixels of the square tile each view is counted on by the GPU (the exact engine
    /// needs none).
    #[arg(long, value_name = "PIXELS", default_value_t = 512)]
    resolution: u32,
    /// Target |error| per counted view: count each view at 64² first and again, up to
    /// --resolution, only where shadow edges make the estimated error larger (see
    /// docs/design.md, "Adaptive resolution"). Without it every view is counted at --resolution.
    #[arg(long, value_name = "A")]
    accuracy: Option<f64>,
}

impl PixelArgs {
    fn options(&self) -> CounterOptions {
        CounterOptions { resolution: self.resolution, accuracy: self.accuracy, ..Default::default() }
    }
}

/// Which engine answers views (fraction, annual, bench).
#[derive(Args)]
struct EngineArgs {
    /// auto: each view on the cheapest of exact clipping, GPU pixels and the compute rasterizer,
    /// by a cost model measured once on this device (see docs/design.md, "Hybrid engine"); gpu:
    /// pixels only (the graphics pipeline); compute: pixels only, counted by the compute
    /// rasterizer (no graphics pipeline); exact: clipping only (see-through nodes count as opaque
    /// there).
    #[arg(long, value_name = "auto|gpu|exact|compute", default_value = "auto")]
    engine: String,
    /// The cost model `auto` routes by: read from FILE when it exists, else measured and written
    /// there (pins the routing); sky views have their own beside it (FILE with `.sky` before its
    /// extension); default: a per-device cache.
    #[arg(long, value_name = "FILE")]
    engine_profile: Option<PathBuf>,
}

impl EngineArgs {
    fn kind(&self) -> Result<EngineKind> {
        EngineKind::parse(&self.engine)
            .map_err(|_| Error::argument("--engine", format!("'{}' is not one of auto, gpu, exact, compute", self.engine)))
    }

    fn source(&self) -> ProfileSource {
        self.engine_profile.clone().map_or(ProfileSource::Cache, ProfileSource::File)
    }
}

#[derive(Args)]
struct FractionArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Sun position: azimuth (degrees clockwise from north), altitude (degrees above the horizon).
    #[arg(long, value_name = "AZ,ALT", allow_hyphen_values = true)]
    sun: String,
    #[command(flatten)]
    pixels: PixelArgs,
    /// Use the exact CPU polygon-clipping reference (slow, one thread: what both engines are tested
    /// against) instead of --engine; see-through nodes count as opaque there.
    #[arg(long)]
    exact: bool,
    #[command(flatten)]
    engine: EngineArgs,
    /// Leaf fraction of foliage, 0 (bare) to 1 (full leaf).
    #[arg(long, value_name = "L", default_value_t = 1.0)]
    leaves: f64,
    /// Print JSON instead of a table (fields in docs/guide-cli.md).
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct InfoArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

fn main() -> ExitCode {
    quiet_mesa_runtime_dir();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    exit_cleanly_on_ctrl_c();
    end_quietly_on_a_closed_pipe();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Fraction(a) => fraction(a),
        Command::Info(a) => info(a),
        Command::Annual(a) => annual(a),
        Command::Bench(a) => run_bench(a),
        Command::Sweep(a) => sweep(a),
        Command::Map(a) => map(a),
        Command::District(a) => district(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", e.render(&flag));
            ExitCode::FAILURE
        }
    }
}

/// `sunlit info MODEL | head` closes the pipe while sunlit still prints: Rust ignores SIGPIPE, so
/// `println!` would panic on the write error. Restoring the default action ends the process
/// quietly at that write, as `cat` or `grep` end; nothing is being written to a file then (every
/// file sunlit writes goes through a temporary file and a rename, and stdout is never one).
fn end_quietly_on_a_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to its default has no preconditions; it runs at
    // start-up, before any other thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Ctrl-C (SIGINT, SIGTERM): remove the temporary file of an output being written, so nothing
/// partial stays beside it, and exit as interrupted (130). Outputs are only written at the end;
/// before that there is nothing to clean.
fn exit_cleanly_on_ctrl_c() {
    let handler = || {
        sunlit::export::remove_partial_files();
        eprintln!("interrupted");
        std::process::exit(130);
    };
    if let Err(e) = ctrlc::set_handler(handler) {
        log::warn!("Ctrl-C will not clean up temporary files: {e}");
    }
}

/// Mesa's Vulkan drivers print "XDG_RUNTIME_DIR is invalid" on every start when it is unset,
/// which reads like a sunlit error; point it at a private folder instead.
fn quiet_mesa_runtime_dir() {
    if !cfg!(target_os = "linux") || std::env::var_os("XDG_RUNTIME_DIR").is_some() {
        return;
    }
    let user = std::env::var("USER").unwrap_or_else(|_| "user".into());
    let dir = std::env::temp_dir().join(format!("sunlit-runtime-{user}"));
    #[cfg(unix)]
    let made = {
        use std::os::unix::fs::DirBuilderExt;
        let created = std::fs::DirBuilder::new().mode(0o700).create(&dir);
        created.is_ok() || dir.is_dir()
    };
    #[cfg(not(unix))]
    let made = false;
    if made {
        // SAFETY: called first thing in main, before any other thread exists.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
    }
}

fn fraction(args: FractionArgs) -> Result<()> {
    let sun = SunPosition::parse(&args.sun)?;
    let leaves = leaf_fraction(args.leaves)?;
    let scene = args.model.load()?;
    let dir = sun.direction();
    let requests: Vec<ViewRequest> =
        (0..scene.receivers.len() as u32).map(|receiver| ViewRequest::new(receiver, dir).with_leaves(leaves)).collect();
    let kind = if args.exact { EngineKind::Exact } else { args.engine.kind()? };
    let answers: Vec<ViewAnswer> = if args.exact {
        pollster::block_on(Exact { scene: &scene }.answer(&requests))?
    } else {
        let engine = HybridEngine::new(&scene, kind, args.pixels.options(), None, args.engine.source())?;
        pollster::block_on(engine.answer(&requests))?
    };
    let method_name = kind.name();
    if args.json {
        let surfaces: Vec<_> = scene
            .receivers
            .iter()
            .zip(&answers)
            .map(|(r, c)| {
                json!({
                    "name": r.name, "fraction": round(c.fraction, 6), "area": round(r.area, 6),
                    "cos_incidence": round(c.cos_incidence, 6), "side": c.side.unwrap_or(0),
                })
            })
            .collect();
        let out = json!({
            "sun": {"azimuth": sun.azimuth, "altitude": sun.altitude},
            "resolution": args.pixels.resolution,
            "accuracy": args.pixels.accuracy,
            "method": method_name,
            "leaves": args.leaves,
            "surfaces": surfaces,
        });
        println!("{out:#}");
        return Ok(());
    }
    let method = match (kind, args.pixels.accuracy) {
        (EngineKind::Exact, _) => "exact polygon clipping".to_string(),
        (EngineKind::Auto, _) => format!("auto: exact clipping or GPU pixels at {0}×{0}, per view", args.pixels.resolution),
        (EngineKind::Gpu, None) => format!("GPU pixel counting, {0}×{0}", args.pixels.resolution),
        (EngineKind::Gpu, Some(a)) => format!("GPU pixel counting, up to {0}×{0} for ±{a}", args.pixels.resolution),
        (EngineKind::Compute, None) => format!("GPU pixel counting by the compute rasterizer, {0}×{0}", args.pixels.resolution),
        (EngineKind::Compute, Some(a)) => {
            format!("GPU pixel counting by the compute rasterizer, up to {0}×{0} for ±{a}", args.pixels.resolution)
        }
    };
    println!("sun azimuth {:.2}°, altitude {:.2}° ({method})", sun.azimuth, sun.altitude);
    let width = scene.receivers.iter().map(|r| r.name.len()).max().unwrap_or(4).max(7);
    println!("{:<width$}  {:>8}  {:>10}  {:>8}", "surface", "fraction", "area m²", "cos θ");
    for (r, c) in scene.receivers.iter().zip(&answers) {
        println!("{:<width$}  {:>8.4}  {:>10.3}  {:>8.4}", r.name, c.fraction, r.area, c.cos_incidence);
    }
    Ok(())
}

/// One static scene's year on the engine the arguments choose; a lost GPU device (driver reset)
/// is recreated once and the year counted again.
/// `annual`'s engine for `scene`, as its flags ask.
fn new_engine<'a>(args: &AnnualArgs, scene: &'a Scene) -> Result<HybridEngine<'a>> {
    HybridEngine::new(scene, args.engine.kind()?, args.pixels.options(), args.lanes, args.engine.source())
}

/// The year of `scene` on `engine` (the caller keeps the engine for the sky views after it).
fn count_year(
    engine: &mut HybridEngine<'_>,
    scene: &Scene,
    settings: &Resolved,
    options: &AnnualOptions,
    meter: &mut progress::Meter,
) -> Result<sunlit::export::Schedule> {
    let year = |engine: &HybridEngine<'_>, meter: &mut progress::Meter| {
        pollster::block_on(sunlit::year::annual::annual_with(engine, scene, &settings.location, options, &settings.calendar, &mut |p| {
            meter.report(p);
            Ok(())
        }))
    };
    // A lost GPU device (driver reset) is recreated once; the year is counted again.
    match year(engine, meter) {
        Err(Error::DeviceLost(why)) => {
            log::warn!("GPU device lost ({why}); making a new one and counting again");
            engine.forget_gpu();
            meter.stage("year, counted again", "views");
            year(engine, meter)
        }
        other => other,
    }
}

fn annual(args: AnnualArgs) -> Result<()> {
    // Everything that can be refused is refused before minutes of counting.
    let mut settings = args.settings()?;
    // Refused now when the location is given; otherwise once the model says where it stands.
    let located = args.epw.is_some() || args.location.is_some();
    if located {
        settings.resolve()?;
    }
    let hook = args.hook.as_deref().map(Hook::parse).transpose()?;
    check_writable(&args.output)?;
    let mut solar = solar_plan(&args)?;
    if let Some(out) = &args.idf_out {
        check_writable(out)?;
    }
    // The Imported form looks up every surface and the Mir- back faces of shading surfaces.
    let loaded = args.model.load_all(hook == Some(Hook::Imported))?;
    let (mut scene, energyplus) = (loaded.scene, loaded.energyplus);
    if !located {
        site_location(&mut settings, energyplus.as_ref())?;
    }
    let settings = settings.resolve()?;
    let periods = energyplus.as_ref().and_then(|e| model::shading_update::periodic_update(&e.objects));
    let mut options = settings.model_options(energyplus.as_ref().and_then(|e| e.timesteps()), periods)?;
    if let Some(p) = periods {
        eprintln!(
            "shading: the model updates EnergyPlus's shading every {} days (Periodic), so each period's days get one sun, the means of \
             its declination and equation of time, as in EnergyPlus's own calculation; a hooked model keeps that update",
            p.days
        );
    }
    let chosen_year = run_year(&args, energyplus.as_ref())?;
    if let Some(plan) = &mut solar {
        plan.year = chosen_year;
    }
    options.timesteps = options.timesteps.leap_year(chosen_year.is_some_and(sunlit::model::run_year::is_leap));
    let timesteps = options.timesteps;
    // Read only for shades with schedules: a holidays record nothing uses is no reason to refuse.
    let weather_days = match &energyplus {
        Some(ep) if !ep.shades.is_empty() => weather_days(&args)?,
        _ => None,
    };
    if let Some(ep) = &energyplus {
        sunlit::model::calendar::check_model(&ep.file, &ep.objects, timesteps.is_leap(), weather_days.as_ref())?;
    }
    let varying = match &energyplus {
        Some(ep) => VaryingShades::for_run(&ep.file, &ep.shades, timesteps, weather_days.as_ref())?,
        None => None,
    };
    if varying.is_some() && hook == Some(Hook::Imported) {
        return Err(Error::argument(
            "--hook",
            "imported: the Imported form makes every shade a receiver, and a receiver is opaque, so a shade whose transmittance schedule changes cannot be hooked that way; use --hook scheduled",
        ));
    }
    if let Some(v) = &varying {
        // Passes that take one scene (the sky views) see each varying shade at its mean τ.
        scene = args.model.load_with_shades(v.mean_transmittance())?;
    }
    let beam = beam_plan(&args, hook, energyplus.as_ref())?;
    let hooked = match (&args.idf_out, &energyplus) {
        (Some(_), None) => return Err(Error::argument("--idf-out", "needs an EnergyPlus model (.idf or .epJSON) among the inputs")),
        (Some(_), Some(ep)) => Some(sunlit::export::hook::hook_for(ep, &scene, hook, timesteps)?),
        (None, _) => None,
    };
    let start = Instant::now();
    // One engine for the year and the sky views after it (its cost model is probed once).
    let mut engine = new_engine(&args, &scene)?;
    let mut meter = progress::Meter::new(if args.dense { "dense year" } else { "year" }, "views")?;
    let schedule = match &varying {
        None => count_year(&mut engine, &scene, &settings, &options, &mut meter)?,
        Some(v) => {
            // Each transmitting shade opaque and removed, mixed per timestep by its τ.
            let mut years = Vec::with_capacity(v.variants());
            for variant in 0..v.variants() {
                if variant > 0 {
                    meter.stage(&format!("year with shades' variant {} of {}", variant + 1, v.variants()), "views");
                }
                let variant_scene = args.model.load_with_shades(v.shade_transmittance(variant))?;
                let mut variant_engine = new_engine(&args, &variant_scene)?;
                years.push(count_year(&mut variant_engine, &variant_scene, &settings, &options, &mut meter)?);
            }
            v.mix(&years)?
        }
    };
    let bytes = schedule.csv_bytes()?;
    // The hooked model is made before anything is written, so a refusal leaves no files.
    let mut patched = match (&args.idf_out, energyplus.as_ref(), hooked) {
        (Some(out), Some(ep), Some(form)) => {
            let text = patch_model(ep, &args.output, &schedule.names, timesteps, form, periods)?;
            let glitches = sunlit::export::glitches::known_glitches(ep, &schedule.names, form);
            Some((out, form, sunlit::export::glitches::with_comments(ep, text, &glitches), glitches))
        }
        _ => None,
    };
    let beam_files = match (&beam, energyplus.as_ref(), patched.as_mut()) {
        (Some(plan), Some(ep), Some((_, _, text, _))) => {
            meter.stage("interior beam", "views");
            let (csv, objects, notes) = beam_outputs(plan, ep, &settings.location, timesteps, periods)?;
            text.push_str(&objects);
            Some((plan.csv.clone(), csv, notes))
        }
        _ => None,
    };
    let solar_files = match &solar {
        Some(plan) => solar_outputs(plan, &engine, &scene, &settings, &schedule, &args, &mut meter)?,
        None => Vec::new(),
    };
    meter.finish();
    sunlit::export::write_atomic(&args.output, &bytes)?;
    for (path, bytes) in &solar_files {
        sunlit::export::write_atomic(path, bytes)?;
        eprintln!("wrote {}", path.display());
    }
    if let Some((path, bytes, notes)) = &beam_files {
        sunlit::export::write_atomic(path, bytes)?;
        eprintln!("wrote {} (the beam onto inside faces, W/m²)", path.display());
        for note in notes {
            eprintln!("note: {note}");
        }
    }
    if let Some((out, form, text, glitches)) = patched {
        sunlit::export::write_atomic(out, text.as_bytes())?;
        eprintln!("wrote {} (EnergyPlus reads {} through {form:?} schedules)", out.display(), args.output.display());
        if let (Hook::Scheduled, Some(ep)) = (form, energyplus.as_ref()) {
            // EnergyPlus's own share: the Scheduled method moves annual site energy even when fed
            // EnergyPlus's own fractions (docs/energyplus-fidelity.md), by cause.
            for cause in sunlit::export::hook::scheduled_method_gap(ep, &schedule.names) {
                eprintln!("note: {cause}");
            }
        }
        // EnergyPlus's own glitches are named, not copied into the model (docs/energyplus-fidelity.md).
        for glitch in &glitches {
            eprintln!("EnergyPlus glitch {}", glitch.line());
        }
    }
    eprintln!(
        "wrote {} ({} rows × {} surfaces) in {:.1} s; {} views counted",
        args.output.display(),
        timesteps.rows(),
        schedule.names.len(),
        start.elapsed().as_secs_f64(),
        meter.counted()
    );
    Ok(())
}

/// Without --epw or --location: the EnergyPlus model's own Site:Location, said so.
fn site_location(settings: &mut AnnualSettings, energyplus: Option<&model::EnergyPlusInput>) -> Result<()> {
    let Some(ep) = energyplus else { return Err(Error::argument("location", "give --epw FILE or --location LAT,LON,TZ")) };
    let Some(site) = model::site::site_location(&ep.file, &ep.objects)? else {
        return Err(Error::argument("location", format!("give --epw FILE or --location LAT,LON,TZ ({} has no Site:Location)", ep.file)));
    };
    eprintln!(
        "location: {}'s Site:Location '{}' ({}° N, {}° E, UTC{:+}); --epw or --location overrides it",
        ep.file, site.name, site.latitude, site.longitude, site.time_zone
    );
    (settings.latitude, settings.longitude, settings.time_zone) = (Some(site.latitude), Some(site.longitude), Some(site.time_zone));
    Ok(())
}

/// The EPW's holidays and daylight saving period (`--epw`), for the shades' schedules.
fn weather_days(args: &AnnualArgs) -> Result<Option<WeatherDays>> {
    let Some(path) = &args.epw else { return Ok(None) };
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.clone(), source })?;
    Ok(Some(WeatherDays::from_epw_text(&path.display().to_string(), &String::from_utf8_lossy(&bytes))?))
}

/// The run's year (`--year`, else the model's RunPeriod, else the EPW's Feb 29), saying which year
/// was chosen and why; `None` (a year of 365 days) when none says.
fn run_year(args: &AnnualArgs, energyplus: Option<&model::EnergyPlusInput>) -> Result<Option<i32>> {
    use sunlit::model::run_year::{YearSource, choose, is_leap};
    let epw = match &args.epw {
        Some(path) => {
            Some(String::from_utf8_lossy(&std::fs::read(path).map_err(|source| Error::Io { path: path.clone(), source })?).into_owned())
        }
        None => None,
    };
    let Some((year, source)) = choose(args.year, energyplus.map(|e| e.objects.as_slice()), epw.as_deref()) else { return Ok(None) };
    let leap = is_leap(year);
    let from = match source {
        YearSource::Given => "--year".to_string(),
        YearSource::RunPeriod => format!("{}'s RunPeriod", energyplus.map_or("", |e| e.file.as_str())),
        YearSource::Weather => "the weather file's Feb 29".to_string(),
    };
    let days = if leap { "a leap year: 366 days, 8784 hours" } else { "365 days, 8760 hours" };
    eprintln!("year: {year} (from {from}), {days}");
    Ok(Some(year))
}

/// The model's text with the CSV hooked in. The CSV is named by its absolute path, so EnergyPlus
/// finds it wherever it is started from and wherever the hooked model is moved to.
fn patch_model(
    ep: &model::EnergyPlusInput,
    csv: &std::path::Path,
    columns: &[String],
    timesteps: Timesteps,
    hook: Hook,
    periods: Option<sunlit::sun::periods::ShadingPeriods>,
) -> Result<String> {
    let folder = std::fs::canonicalize(csv.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(std::path::Path::new(".")))
        .map_err(|source| Error::Io { path: csv.to_path_buf(), source })?;
    let csv_text = match csv.file_name() {
        Some(name) => folder.join(name).display().to_string(),
        None => csv.display().to_string(),
    };
    // An IDF field ends at ',' or ';' and a comment starts at '!': such a path cannot be written.
    if !ep.epjson && csv_text.contains([',', ';', '!']) {
        return Err(Error::argument(
            "output",
            format!("'{csv_text}': an IDF field cannot hold ',', ';' or '!'; choose a path without them"),
        ));
    }
    sunlit::export::hook::patch_model(ep, &HookPlan { csv: &csv_text, columns, timesteps, hook, periods })
}

/// Fails early, before any counting, when the output folder cannot take the file.
fn check_writable(path: &std::path::Path) -> Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let probe = dir.join(format!(".sunlit-probe-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let _ = std::fs::remove_file(&probe);
    if path.is_dir() {
        return Err(Error::argument("--output", format!("{} is a folder", path.display())));
    }
    Ok(())
}

fn round(x: f64, digits: i32) -> f64 {
    let k = 10f64.powi(digits);
    (x * k).round() / k
}

fn info(args: InfoArgs) -> Result<()> {
    let loaded = args.model.load_all(false)?;
    let (scene, notes) = (loaded.scene, loaded.notes);
    let receivers: Vec<_> = scene
        .receivers
        .iter()
        .map(|r| json!({"name": r.name, "area": round(r.area, 6), "normal": [round(r.normal.x, 6), round(r.normal.y, 6), round(r.normal.z, 6)], "source": r.origin}))
        .collect();
    let (lo, hi) = scene.bounds;
    if args.json {
        let out = json!({
            "receivers": receivers,
            "triangles": scene.triangle_count(),
            "meshes": scene.meshes.len(),
            "instances": scene.instances.len(),
            "leaves": scene.veil_counts().0,
            "see_through_triangles": scene.veil_counts().1,
            "bounds": {"min": [lo.x, lo.y, lo.z], "max": [hi.x, hi.y, hi.z]},
            "notes": notes,
        });
        println!("{out:#}");
        return Ok(());
    }
    println!(
        "{} receivers; {} triangles cast shadows ({} shared meshes, {} placements); bounds ({:.2}, {:.2}, {:.2}) – ({:.2}, {:.2}, {:.2}) m",
        scene.receivers.len(),
        scene.triangle_count(),
        scene.meshes.len() - 1,
        scene.instances.len() - 1,
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z
    );
    for note in &notes {
        println!("note: {note}");
    }
    let (leaves, see_through) = scene.veil_counts();
    if leaves + see_through > 0 {
        println!("foliage: {leaves} leaves; see-through: {see_through} triangles");
    }
    let width = scene.receivers.iter().map(|r| r.name.len()).max().unwrap_or(4).max(7);
    println!("{:<width$}  {:>10}  normal (x east, y north, z up)", "surface", "area m²");
    // Rounded first, then + 0.0: a component a hair below zero prints as +0.000, never -0.000.
    let tidy = |v: f64| round(v, 3) + 0.0;
    for r in &scene.receivers {
        println!("{:<width$}  {:>10.3}  ({:+.3}, {:+.3}, {:+.3})", r.name, r.area, tidy(r.normal.x), tidy(r.normal.y), tidy(r.normal.z));
    }
    Ok(())
}
