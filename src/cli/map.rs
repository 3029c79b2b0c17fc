//! `sunlit map`, the CLI's edge of [`sunlit::map`]: its flags, the period they describe, the
//! points CSV, the map glb and the study reports. The library owns the points, the rays, the
//! sums and the rules.

use serde_json::Value;
use sunlit::export::map_glb::map_glb;
use sunlit::export::map_table::{Column, points_csv, study_csv, study_json, value_columns};
use sunlit::export::write_atomic;
use sunlit::map::period::{parse_clock, parse_date};
use sunlit::map::planning::window_points::{WindowPoint, floor_sills, window_points};
use sunlit::map::study::{self, SunRule};
use sunlit::map::{MapGpu, MapValues, Mapper, Period, Points, Site, point_sky_for};
use sunlit::sky::model::SkyModel;
use sunlit::sky::patches::SkyPatches;
use sunlit::sun::weather::{Weather, check_albedo};
use sunlit::year::season::LeafCalendar;

use super::progress::Meter;
use super::*;

#[path = "map_inside.rs"]
mod inside;
#[path = "map_planning.rs"]
mod planning;
#[path = "map_pv.rs"]
mod pv;

#[derive(Args)]
#[command(group = clap::ArgGroup::new("site").args(["epw", "location"]))]
pub(super) struct MapArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// A grid on every receiver at this spacing in metres (the default, at 0.5 m).
    #[arg(long, value_name = "SPACING", conflicts_with = "points")]
    grid: Option<f64>,
    /// Points from a CSV with the header x,y,z,nx,ny,nz (world axes, metres), each on a receiver.
    #[arg(long, value_name = "FILE.csv")]
    points: Option<PathBuf>,
    /// Window studies: one point per receiver (each a window), found from its geometry: centre
    /// (BRE's reference point, the window's centre) or sill (GB 50180's, its lowest edge's middle).
    #[arg(long, value_name = "centre|sill", conflicts_with_all = ["points", "grid"])]
    window_points: Option<String>,
    /// With --window-points sill: the ground floor's level (m, the model's height); a window
    /// reaching lower than 0.9 m above it (one reaching the floor) is counted 0.9 m above it, as
    /// GB 50180 takes its sill.
    #[arg(long, value_name = "Z", allow_hyphen_values = true)]
    floor_level: Option<f64>,
    /// Weather file: the site and its solar data (adds direct_kwh_m2, sky_diffuse_kwh_m2,
    /// ground_reflected_kwh_m2 and total_kwh_m2).
    #[arg(long, value_name = "FILE.epw")]
    epw: Option<PathBuf>,
    /// Ground reflectance (0..1) for every hour, with --epw; default: the EPW's albedo (field 33),
    /// 0.2 where it is missing.
    #[arg(long, value_name = "R", allow_hyphen_values = true)]
    albedo: Option<f64>,
    /// Sky patches for each point's sky views, with --epw: tregenza (145, the default) or
    /// reinhart:N (N = 1..6, 144·N² + 1 patches).
    #[arg(long, value_name = "SCHEME")]
    sky_patches: Option<String>,
    /// Site without weather: latitude, longitude, time zone (sun hours only).
    #[arg(long, value_name = "LAT,LON,TZ", allow_hyphen_values = true)]
    location: Option<String>,
    /// annual, one day MM-DD, or days MM-DD..MM-DD (default annual; a study's day with --study).
    #[arg(long, value_name = "annual|MM-DD|MM-DD..MM-DD")]
    period: Option<String>,
    /// Minutes between instants: an EnergyPlus timestep over days (default 60), 1–60 dividing the
    /// window on one day (default 10; 1 for studies).
    #[arg(long, value_name = "MINUTES")]
    step: Option<u32>,
    /// Start of a one-day window, local standard time (default 00:00).
    #[arg(long, value_name = "HH:MM")]
    from: Option<String>,
    /// End of a one-day window (default 24:00).
    #[arg(long, value_name = "HH:MM")]
    to: Option<String>,
    /// One instant: date and local standard time; writes a lit column (1 lit, 0 shaded).
    #[arg(long, num_args = 2, value_names = ["MM-DD", "HH:MM"], conflicts_with_all = ["period", "from", "to", "step", "study"])]
    at: Option<Vec<String>>,
    /// The points CSV to write.
    #[arg(short = 'o', long = "output", value_name = "POINTS.csv")]
    output: PathBuf,
    /// Also write the receivers coloured by the value as a glb (legend in the scene's extras).
    #[arg(long, value_name = "MAP.glb")]
    glb_out: Option<PathBuf>,
    /// Study: bre-ground or en17037 (sun hours on areas), or the window studies bre-vsc,
    /// bre-apsh, gb50180, bre-25deg, bre-45deg, and en17037 beside them or with --window-points
    /// or --before (per reference point; docs/planning.md); repeatable. Reports go beside the
    /// output as POINTS.study-NAME.json and .csv.
    #[arg(long, value_name = "NAME")]
    study: Vec<String>,
    /// Minimum sun altitude (degrees) for en17037, the area or the window study (default 10).
    #[arg(long, value_name = "DEGREES")]
    min_altitude: Option<f64>,
    /// Who answers each point: exact (a shadow ray through the exact engine's BVH), gpu (its
    /// texel in the GPU's sun-view tile of its receiver), or auto (exact: see docs/maps.md).
    #[arg(long, value_name = "auto|gpu|exact", default_value = "auto")]
    engine: String,
    /// With --engine gpu: side in pixels of the square tile each receiver is rendered on.
    #[arg(long, value_name = "PIXELS", default_value_t = 512)]
    resolution: u32,
    /// Map the inside of an EnergyPlus model's zones: points on the inside faces of their
    /// surfaces or free in them, the beam through the windows (see docs/maps.md, "The sun inside").
    #[arg(long)]
    inside: bool,
    /// With --inside and a glTF (or OBJ) model: mesh nodes that are rooms, each a closed shell
    /// named after its node (glob over node names, case-insensitive; repeatable).
    #[arg(long, value_name = "GLOB", requires = "inside")]
    interior: Vec<String>,
    /// With --interior: mesh nodes that are glass, left out as openings and letting
    /// --glass-transmittance through (glob over node names; repeatable).
    #[arg(long, value_name = "GLOB", requires = "interior")]
    glazing: Vec<String>,
    /// With --inside: transmittance (0..1) of glazing whose construction is not a
    /// WindowMaterial:SimpleGlazingSystem, and of every --glazing node.
    #[arg(long, value_name = "T", allow_hyphen_values = true)]
    glass_transmittance: Option<f64>,
    /// With --inside and an EnergyPlus model: the solar transmittance by angle of incidence of
    /// glazing whose construction sunlit cannot read, ANGLE:T pairs from 0° (degrees, never
    /// rising), e.g. 0:0.6,40:0.58,60:0.5,80:0.25; --glass-transmittance then gives the visible
    /// value (else the curve's at 0°), which falls off in the same proportion.
    #[arg(long, value_name = "ANGLE:T,...", requires = "inside")]
    glass_curve: Option<String>,
    /// With --inside and a grid: put it this many metres above each floor (default 0: on the
    /// floors; 0.76 with --study leed-ase).
    #[arg(long, value_name = "METRES", allow_hyphen_values = true)]
    work_plane: Option<f64>,
    /// With --inside and a grid: put it on every inside face of the rooms (walls, roofs and
    /// ceilings at the grid's spacing besides the floors or work plane), so a sun patch at an
    /// instant is mapped on each face it falls on.
    #[arg(long, requires = "inside", conflicts_with = "points")]
    faces: bool,
    /// Print a JSON summary.
    #[arg(long)]
    json: bool,
    /// Also write each point's beam shaded fraction per timestep on pvlib's time index, one column
    /// point_I per row I of the points CSV (annual; docs/district.md shows the pvlib code).
    #[arg(long, value_name = "FILE.csv")]
    pvlib: Option<PathBuf>,
    /// Also write SAM pvsamv1's shading inputs for the points taken as one array (annual; needs
    /// --epw).
    #[arg(long, value_name = "FILE.json")]
    sam: Option<PathBuf>,
    /// Window studies (bre-vsc, bre-apsh, gb50180): the existing scene's models; each point's
    /// former values go beside the proposed ones, with BRE's relative tests. Needs --points or --window-points.
    /// With --inside --study bre-nsl: the existing model, its rooms read as the proposed one's;
    /// each room's former share of working plane seeing sky, the ratio and BRE's 0.8 rule.
    #[arg(long, value_name = "MODEL", num_args = 1..)]
    before: Vec<PathBuf>,
    /// gb50180's standard day: dahan (大寒日, the default) or dongzhi (冬至日).
    #[arg(long, value_name = "dahan|dongzhi")]
    day: Option<String>,
    /// gb50180: hours a sill must reach (default 2 on dahan, 1 on dongzhi).
    #[arg(long, value_name = "HOURS")]
    required_hours: Option<f64>,
    /// gb50180: only continuous periods at least this long count (minutes; default 0).
    #[arg(long, value_name = "MINUTES")]
    min_period: Option<f64>,
    /// gb50180: only the longest N periods count (default all).
    #[arg(long, value_name = "N")]
    max_periods: Option<usize>,
    /// gb50180: also the 满窗 (whole window) hours, the sun over the whole sill: one width (m)
    /// for every window, centred on each point, or `sill`, each window's own sill line measured
    /// from its geometry (with --window-points sill).
    #[arg(long, value_name = "METRES|sill")]
    window_width: Option<String>,
    /// gb50180: the 满窗 hours with each window's own sill width, from a CSV `receiver,width`
    /// (instead of one --window-width).
    #[arg(long, value_name = "FILE.csv")]
    window_widths: Option<PathBuf>,
    /// The sky that weighs the patches, with --epw: energyplus (the default), perez-all-weather
    /// (Radiance's gendaymtx sky), cie-overcast or uniform; bre-vsc takes only cie-overcast (its
    /// definition).
    #[arg(long, value_name = "NAME")]
    sky_model: Option<String>,
    /// Window studies: sky-mask diagrams (stereographic, with sun paths) for these 1-based point
    /// rows, or all: POINTS.mask-N.svg.
    #[arg(long, value_name = "ROWS|all")]
    mask: Option<String>,
    /// Window studies: a self-contained HTML report (tables with pass/fail, masks, rules).
    #[arg(long, value_name = "REPORT.html")]
    html: Option<PathBuf>,
}

/// What the flags ask for, checked before the model is read.
struct Plan {
    period: Period,
    rules: Vec<SunRule>,
    instant: bool,
}

impl MapArgs {
    fn plan(&self) -> Result<Plan> {
        if let Some(at) = &self.at {
            let day = parse_date("at", &at[0])?;
            let minute = parse_clock("at", &at[1])?;
            return Ok(Plan { period: Period::at(day, minute)?, rules: Vec::new(), instant: true });
        }
        let mut rules: Vec<SunRule> =
            self.study.iter().filter(|s| !inside::STUDIES.contains(&s.as_str())).map(|s| study::preset(s)).collect::<Result<_>>()?;
        if let Some(a) = self.min_altitude {
            if !(0.0..90.0).contains(&a) {
                return Err(Error::argument("min_altitude", format!("{a}° is not in 0..90")));
            }
            for r in rules.iter_mut().filter(|r| r.name == "en17037") {
                r.min_altitude_deg = a;
            }
        }
        let text = self.period.as_deref().unwrap_or(if rules.is_empty() { "annual" } else { "" });
        let (from, to) = (
            self.from.as_deref().map(|t| parse_clock("from", t)).transpose()?,
            self.to.as_deref().map(|t| parse_clock("to", t)).transpose()?,
        );
        let one_day =
            |day: u32, default_step: u32| Period::day(day, from.unwrap_or(0), to.unwrap_or(24 * 60), self.step.unwrap_or(default_step));
        let period = if text.is_empty() {
            // Studies without a period: their (shared) default day.
            let day = rules[0].default_day;
            one_day(day, 1)?
        } else if text == "annual" || text.contains("..") {
            if from.is_some() || to.is_some() {
                return Err(Error::argument("from", "--from and --to need a one-day --period MM-DD"));
            }
            let step = self.step.unwrap_or(60);
            if step == 0 || !60u32.is_multiple_of(step) {
                return Err(Error::argument(
                    "step",
                    format!("{step} min: over days the step must divide the hour as an EnergyPlus timestep does"),
                ));
            }
            match text.split_once("..") {
                None => Period::annual(60 / step)?,
                Some((a, b)) => Period::days(parse_date("period", a)?, parse_date("period", b)?, 60 / step)?,
            }
        } else {
            one_day(parse_date("period", text)?, if rules.is_empty() { 10 } else { 1 })?
        };
        for rule in &rules {
            let Some(day) = period.single_day() else {
                return Err(Error::argument("study", format!("{} evaluates one day; give --period MM-DD, not '{text}'", rule.name)));
            };
            rule.check_day(day)?;
        }
        Ok(Plan { period, rules, instant: false })
    }

    fn points(&self, scene: &Scene) -> Result<Points> {
        let all: Vec<u32> = (0..scene.receivers.len() as u32).collect();
        if let Some(at) = &self.window_points {
            return match (WindowPoint::parse(at)?, self.floor_level) {
                (WindowPoint::Sill, Some(floor)) => floor_sills(scene, &all, floor),
                (at, _) => window_points(scene, &all, at),
            };
        }
        match &self.points {
            Some(path) => {
                let text = std::fs::read_to_string(path).map_err(|source| Error::Io { path: path.clone(), source })?;
                sunlit::map::from_csv(scene, &path.display().to_string(), &text, &all)
            }
            None => sunlit::map::grid(scene, self.grid.unwrap_or(0.5), &all),
        }
    }

    /// Whether the GPU answers the points: `auto` picks the exact rays (docs/maps.md says why).
    fn on_gpu(&self) -> Result<bool> {
        let kind = EngineKind::parse(&self.engine)
            .map_err(|_| Error::argument("--engine", format!("'{}' is not one of auto, gpu, exact", self.engine)))?;
        if kind == EngineKind::Compute {
            // Map points are read from the raster kernel's atlas, which the compute kernel has not.
            return Err(Error::argument("--engine", "'compute' draws no atlas for map points to read: use gpu, exact or auto"));
        }
        Ok(kind == EngineKind::Gpu)
    }

    /// The site and its weather (with `--albedo` applied), once the output paths are known to be
    /// writable.
    fn site(&self) -> Result<(Location, Option<Weather>)> {
        let (location, weather) = match (&self.epw, &self.location) {
            (Some(epw), _) => {
                let weather = Weather::from_epw(epw)?;
                let weather = match self.albedo {
                    Some(albedo) => weather.with_albedo(albedo)?,
                    None => weather,
                };
                (weather.location.clone(), Some(weather))
            }
            (None, Some(text)) => (Location::parse(text)?, None),
            (None, None) => return Err(Error::argument("location", "give --epw FILE or --location LAT,LON,TZ")),
        };
        check_writable(&self.output)?;
        if let Some(glb) = &self.glb_out {
            check_writable(glb)?;
        }
        Ok((location, weather))
    }

    fn study_path(&self, name: &str, extension: &str) -> PathBuf {
        let stem = self.output.file_stem().map_or("map".into(), |s| s.to_string_lossy().into_owned());
        self.output.with_file_name(format!("{stem}.study-{name}.{extension}"))
    }
}

pub(super) fn map(args: MapArgs) -> Result<()> {
    if planning::wanted(&args) {
        return planning::run(args);
    }
    let window_only = [
        ("--before", !args.before.is_empty() && !args.study.iter().any(|s| s == "bre-nsl")),
        ("--day", args.day.is_some()),
        ("--required-hours", args.required_hours.is_some()),
        ("--min-period", args.min_period.is_some()),
        ("--max-periods", args.max_periods.is_some()),
        ("--window-width", args.window_width.is_some()),
        ("--window-widths", args.window_widths.is_some()),
        ("--window-points", args.window_points.is_some()),
        ("--floor-level", args.floor_level.is_some()),
        ("--mask", args.mask.is_some()),
        ("--html", args.html.is_some()),
    ];
    if let Some((flag, _)) = window_only.iter().find(|(_, given)| *given) {
        return Err(Error::argument(*flag, format!("is taken by the window studies only ({})", planning::STUDIES.join(", "))));
    }
    if args.inside || args.study.iter().any(|s| inside::STUDIES.contains(&s.as_str())) {
        if args.sky_model.is_some() {
            return Err(Error::argument("--sky-model", "the inside map counts the beam through the windows and takes no sky model"));
        }
        return inside::map_inside(args);
    }
    let plan = args.plan()?;
    let on_gpu = args.on_gpu()?;
    pv::check(&args, &plan, on_gpu)?;
    if let Some(g) = args.grid
        && !(g.is_finite() && g > 0.0)
    {
        return Err(Error::argument("spacing", format!("{g} m: a grid spacing must be a positive number of metres")));
    }
    let patches = SkyPatches::parse(args.sky_patches.as_deref().unwrap_or("tregenza"))?;
    if let Some(albedo) = args.albedo {
        check_albedo(albedo)?;
        if args.epw.is_none() {
            return Err(Error::argument("albedo", "needs a weather file (--epw): the ground reflects its global horizontal irradiance"));
        }
    }
    if args.sky_patches.is_some() && args.epw.is_none() {
        return Err(Error::argument("sky_patches", "needs a weather file (--epw): the sky's light comes from it"));
    }
    let model = args.sky_model.as_deref().map_or(Ok(SkyModel::EnergyPlus), SkyModel::parse)?;
    if args.sky_model.is_some() && args.epw.is_none() {
        return Err(Error::argument("sky_model", "needs a weather file (--epw): the sky's light comes from it"));
    }
    let (location, weather) = args.site()?;
    let scene = args.model.load()?;
    let points = args.points(&scene)?;
    let start = Instant::now();
    let mapper = Mapper::new(&scene, &points)?;
    let counter = if on_gpu {
        Some(pollster::block_on(Counter::new(CounterOptions { resolution: args.resolution, ..Default::default() }))?)
    } else {
        None
    };
    let gpu = counter.as_ref().map(|c| MapGpu::new(c, &scene, &points)).transpose()?;
    let calendar = LeafCalendar::for_latitude(location.latitude);
    let samples = plan.period.samples();
    // Each point's own sky views, once (geometry only), when irradiation is summed.
    let sky_start = Instant::now();
    let mut meter = Meter::new(&format!("{} points: sky views ({} patches)", points.len(), patches.len()), "patch views")?;
    let sky = (weather.is_some() && !plan.instant).then(|| point_sky_for(&mapper, &patches, model, &mut meter.counts()));
    meter.stage(&format!("{} points", points.len()), "instants");
    let sky_seconds = sky_start.elapsed().as_secs_f64();
    let site = Site { location: &location, calendar: &calendar, weather: weather.as_ref(), sky: sky.as_ref() };

    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    let mut summary = json!({});
    let (csv, glb_values, glb_name, glb_unit) = if plan.instant {
        let s = samples[0];
        let sun = sunlit::sun::position::sun_direction(&location, sunlit::year::annual::shading_sun_day(s.day), s.hour);
        let leaves = calendar.fraction(f64::from(s.day)) as f32;
        let lit = match &gpu {
            Some(g) => pollster::block_on(mapper.visibility_gpu(g, sun, leaves))?,
            None => mapper.visibility(sun, leaves),
        };
        let lit: Vec<f64> = lit.into_iter().map(f64::from).collect();
        let csv = points_csv(&scene, &points, &[Column { name: "lit", values: &lit, decimals: 0 }]);
        summary["lit_points"] = json!(lit.iter().filter(|&&v| v >= 0.5).count());
        summary["sun_up"] = json!(sun.z >= sunlit::count::MIN_COS_INCIDENCE);
        (csv, lit, "lit", "")
    } else {
        let values = match &gpu {
            Some(g) => pollster::block_on(mapper.accumulate_gpu(g, &samples, site, &mut meter.counts()))?,
            None => mapper.accumulate(&samples, site, &mut meter.counts())?,
        };
        let csv = points_csv(&scene, &points, &value_columns(&values));
        summary["sun_up_instants"] = json!(values.sun_up);
        if pv::wanted(&args) {
            files.extend(pv::outputs(&args, &mapper, &points, &samples, site, &values, &mut meter)?);
        }
        let mut studies = Vec::new();
        for rule in &plan.rules {
            meter.stage(&format!("{} points: {}", points.len(), rule.name), "instants");
            let series = match &gpu {
                Some(g) => pollster::block_on(mapper.lit_series_gpu(g, &samples, site, rule.min_altitude_deg, &mut meter.counts()))?,
                None => mapper.lit_series(&samples, site, rule.min_altitude_deg, &mut meter.counts()),
            };
            let day = plan.period.single_day().unwrap_or(rule.default_day);
            let result = study::evaluate(rule, day, &samples, &series, &points.receivers);
            let inputs = json!({
                "models": args.model.models,
                "points": args.points.as_ref().map_or(json!({"grid_spacing_m": args.grid.unwrap_or(0.5)}), |p| json!({"file": p})),
                "site": {"latitude": location.latitude, "longitude": location.longitude, "time_zone": location.time_zone},
                "step_minutes": samples.first().map(|s| s.hours * 60.0),
            });
            let report_json = study_json(&scene, &points, &result, inputs);
            studies.push(json!({"study": rule.name, "areas": report_json["areas"].clone()}));
            files.push((args.study_path(&rule.name, "json"), format!("{report_json:#}\n").into_bytes()));
            files.push((args.study_path(&rule.name, "csv"), study_csv(&scene, &points, &result).into_bytes()));
        }
        summary["studies"] = Value::Array(studies);
        let (name, unit, v) = glb_value(values);
        (csv, v, name, unit)
    };
    meter.finish();
    files.insert(0, (args.output.clone(), csv.into_bytes()));
    if let Some(glb) = &args.glb_out {
        files.push((glb.clone(), map_glb(&scene, &points, &glb_values, glb_name, glb_unit)));
    }
    for (path, bytes) in &files {
        write_atomic(path, bytes)?;
    }
    let seconds = start.elapsed().as_secs_f64();
    summary["points"] = json!(points.len());
    summary["instants"] = json!(samples.len());
    summary["seconds"] = json!(round(seconds, 3));
    let point_instants = points.len() * samples.len();
    summary["engine"] = match &gpu {
        Some(g) => json!({
            "exact_rays": 0,
            "gpu_masks": point_instants,
            "gpu_masks_rendered": g.rendered(),
            "resolution": args.resolution,
            "adapter": counter.as_ref().map(|c| c.adapter_info().name.clone()),
        }),
        None => json!({"exact_rays": point_instants, "gpu_masks": 0}),
    };
    if let Some(sky) = &sky {
        summary["sky"] = json!({"patches": sky.patches.name(), "model": sky.model().name(), "count": sky.patches.len(), "leaf_states": sky.leaf_states.len(), "seconds": round(sky_seconds, 3)});
    }
    summary["written"] = json!(files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>());
    if args.json {
        println!("{summary:#}");
    } else {
        eprintln!("{} points × {} instants in {seconds:.2} s → {}", points.len(), samples.len(), args.output.display());
    }
    Ok(())
}

/// The glb's value: total irradiation with the sky, else direct with an EPW, else sun hours.
fn glb_value(values: MapValues) -> (&'static str, &'static str, Vec<f64>) {
    match (values.total_kwh_m2, values.direct_kwh_m2) {
        (Some(t), _) => ("total_kwh_m2", "kWh/m²", t),
        (None, Some(d)) => ("direct_kwh_m2", "kWh/m²", d),
        (None, None) => ("sun_hours", "h", values.sun_hours),
    }
}
