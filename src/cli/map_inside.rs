//! `sunlit map --inside`, the CLI's edge of [`sunlit::map::inside`]: the rooms of one EnergyPlus
//! model, their points, and the instant, period or LEED ASE outputs. The library owns the rooms,
//! the glass, the sums and the rule.

use sunlit::export::map_table::{ase_column, inside_instant_columns, inside_period_columns, inside_period_shown};
use sunlit::map::inside::{
    self as rooms_map, ASE_HOURS, ASE_LUX, ASE_SPACING, BEAM_EFFICACY, InsideMap, NSL_WORK_PLANE, OCCUPIED, RoomPoints, WORK_PLANE_HEIGHT,
};
use sunlit::map::planning::compare::FORMER_RATIO;
use sunlit::model::inside::curve::TransmittanceCurve;
use sunlit::model::inside::gltf::rooms as gltf_rooms;
use sunlit::model::inside::{Rooms, UnreadGlass, inside_scene, rooms_with};

use super::*;

/// The studies `--inside` answers.
pub(super) const STUDIES: [&str; 2] = ["leed-ase", "bre-nsl"];

/// What the flags ask of the inside, checked before the model is read.
enum Ask {
    /// One instant.
    At(Period),
    /// Sums over a period.
    Period(Period),
    /// LEED v4.1 ASE over the year.
    Ase,
    /// BRE 209's No-Sky Line.
    Nsl,
}

fn ask(args: &MapArgs) -> Result<Ask> {
    if !args.inside {
        return Err(Error::argument("study", "leed-ase and bre-nsl map the inside of rooms: add --inside"));
    }
    if args.study.len() > 1 {
        return Err(Error::argument("study", "one study of the inside at a time (their work planes differ)"));
    }
    if let Some(other) = args.study.iter().find(|s| !STUDIES.contains(&s.as_str())) {
        return Err(Error::argument("study", format!("'{other}' is not a study of the inside (known: {})", STUDIES.join(", "))));
    }
    if args.engine != "auto" && args.engine != "exact" {
        return Err(Error::argument(
            "engine",
            "the inside is mapped by the exact engine's rays only (free planes are no geometry to draw)",
        ));
    }
    if args.faces && !args.study.is_empty() {
        return Err(Error::argument("faces", "a study's share is of the work plane alone: drop --faces"));
    }
    if args.study.iter().any(|s| s == "bre-nsl") {
        if args.period.is_some() || args.at.is_some() {
            return Err(Error::argument("study", "bre-nsl is geometry (which points see sky); drop --period and --at"));
        }
        return Ok(Ask::Nsl);
    }
    if !args.study.is_empty() {
        if args.epw.is_none() {
            return Err(Error::argument("study", "leed-ase needs --epw (direct normal illuminance, or irradiance)"));
        }
        if args.period.is_some() || args.step.is_some() || args.from.is_some() || args.to.is_some() {
            return Err(Error::argument("study", "leed-ase is the year at hourly steps; drop --period, --step, --from and --to"));
        }
        return Ok(Ask::Ase);
    }
    let plan = args.plan()?;
    Ok(if plan.instant { Ask::At(plan.period) } else { Ask::Period(plan.period) })
}

pub(super) fn map_inside(args: MapArgs) -> Result<()> {
    let ask = ask(&args)?;
    if let Some(g) = args.grid
        && !(g.is_finite() && g > 0.0)
    {
        return Err(Error::argument("spacing", format!("{g} m: a grid spacing must be a positive number of metres")));
    }
    unread_glass(&args)?;
    let (location, weather) = args.site()?;
    let (mut scene, rooms) = read_rooms(&args, &args.model)?;
    let defaults = match ask {
        Ask::Ase => (ASE_SPACING, WORK_PLANE_HEIGHT),
        Ask::Nsl => (0.5, NSL_WORK_PLANE),
        _ => (0.5, 0.0),
    };
    let at = room_points(&args, &mut scene, &rooms, defaults)?;
    let start = Instant::now();
    let mapper = Mapper::new(&scene, &at.points)?;
    let map = InsideMap { mapper: &mapper, rooms: &rooms, at: &at };
    let calendar = LeafCalendar::for_latitude(location.latitude);
    let site = Site { location: &location, calendar: &calendar, weather: weather.as_ref(), sky: None };
    let mut summary = json!({});
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    let (csv, glb) = match ask {
        Ask::At(period) => instant(&scene, map, &period, &location, &calendar, &mut summary),
        Ask::Period(period) => {
            let samples = period.samples();
            let values = rooms_map::accumulate(map, &samples, site, &mut |_, _| {});
            summary["instants"] = json!(values.instants);
            summary["efficacy_hours"] = json!(values.efficacy_hours);
            let csv = points_csv(&scene, &at.points, &inside_period_columns(&values));
            let (name, unit, shown) = inside_period_shown(&values);
            (csv, (name, unit, shown.to_vec()))
        }
        Ask::Ase => {
            let samples = rooms_map::occupied_hours(&Period::annual(1)?.samples());
            let result = rooms_map::leed_ase(map, &samples, site, &mut |_, _| {})?;
            let report = ase_report(&args, &location, &result, &at);
            summary["studies"] = json!([{"study": "leed-ase", "areas": report["areas"].clone()}]);
            files.push((args.study_path("leed-ase", "json"), format!("{report:#}\n").into_bytes()));
            (points_csv(&scene, &at.points, &[ase_column(&result)]), ("hours_over_1000_lux", "h", result.hours.clone()))
        }
        Ask::Nsl => {
            let patches = SkyPatches::parse(args.sky_patches.as_deref().unwrap_or("tregenza"))?;
            let (sees, areas) = rooms_map::no_sky_line(map, &patches, &mut |_, _| {});
            let former = if args.before.is_empty() { None } else { Some(nsl_before(&args, defaults, &patches)?) };
            let report = nsl_report(&args, &patches, &areas, former.as_ref());
            summary["studies"] = json!([{"study": "bre-nsl", "areas": report["areas"].clone()}]);
            files.push((args.study_path("bre-nsl", "json"), format!("{report:#}\n").into_bytes()));
            let sees: Vec<f64> = sees.iter().map(|&s| f64::from(u8::from(s))).collect();
            // The existing model's points go beside only where they are the same points.
            let same = former.as_ref().filter(|(_, _, points)| *points == at.points.positions);
            let before: Option<Vec<f64>> = same.map(|(s, _, _)| s.iter().map(|&s| f64::from(u8::from(s))).collect());
            let mut columns = vec![Column { name: "sees_sky", values: &sees, decimals: 0 }];
            if let Some(b) = &before {
                columns.push(Column { name: "sees_sky_before", values: b, decimals: 0 });
            }
            (points_csv(&scene, &at.points, &columns), ("sees_sky", "", sees.clone()))
        }
    };
    files.insert(0, (args.output.clone(), csv.into_bytes()));
    if let Some(path) = &args.glb_out {
        files.push((path.clone(), map_glb(&scene, &at.points, &glb.2, glb.0, glb.1)));
    }
    for (path, bytes) in &files {
        write_atomic(path, bytes)?;
    }
    summary["points"] = json!(at.points.len());
    summary["rooms"] = json!(rooms.rooms.len());
    summary["seconds"] = json!(round(start.elapsed().as_secs_f64(), 3));
    summary["engine"] = json!({"exact_rays": at.points.len(), "gpu_masks": 0});
    summary["written"] = json!(files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>());
    if args.json {
        println!("{summary:#}");
    } else {
        eprintln!("{} points in {} rooms → {}", at.points.len(), rooms.rooms.len(), args.output.display());
    }
    Ok(())
}

/// The rooms' points: `--points`, else a grid (`--grid`, `--work-plane`, else `defaults`:
/// spacing and height) on their floors, and with `--faces` on every other inside face too.
fn room_points(args: &MapArgs, scene: &mut Scene, rooms: &Rooms, defaults: (f64, f64)) -> Result<RoomPoints> {
    match &args.points {
        Some(path) => {
            let text = std::fs::read_to_string(path).map_err(|source| Error::Io { path: path.clone(), source })?;
            rooms_map::room_points_csv(scene, rooms, &path.display().to_string(), &text)
        }
        None => {
            let grid = if args.faces { rooms_map::face_grid } else { rooms_map::floor_grid };
            grid(scene, rooms, args.grid.unwrap_or(defaults.0), args.work_plane.unwrap_or(defaults.1))
        }
    }
}

/// The existing model's No-Sky Line: per point whether it sees sky, per room the share, and the
/// points' positions.
type Former = (Vec<bool>, Vec<rooms_map::NslArea>, Vec<f32>);

/// The No-Sky Line of the existing model (`--before`): its rooms, read as the proposed model's
/// are, on the same kind of points. Per point whether it sees sky, per room the share, and the
/// points' positions (to put them beside the proposed ones when they are the same).
fn nsl_before(args: &MapArgs, defaults: (f64, f64), patches: &SkyPatches) -> Result<Former> {
    let mut model = args.model.clone();
    model.models = args.before.clone();
    let (mut scene, rooms) = read_rooms(args, &model)?;
    let at = room_points(args, &mut scene, &rooms, defaults)?;
    let mapper = Mapper::new(&scene, &at.points)?;
    let (sees, areas) = rooms_map::no_sky_line(InsideMap { mapper: &mapper, rooms: &rooms, at: &at }, patches, &mut |_, _| {});
    Ok((sees, areas, at.points.positions))
}

/// `POINTS.study-bre-nsl.json`: per room `zone`, `points`, `sees_sky` (%), and with `--before`
/// the former share, the ratio and BRE 209's 0.8 × former value test.
fn nsl_report(args: &MapArgs, patches: &SkyPatches, areas: &[rooms_map::NslArea], former: Option<&Former>) -> Value {
    let rows: Vec<Value> = match former {
        None => areas.iter().map(|a| json!({"zone": a.zone, "points": a.points, "sees_sky": round(a.sees_sky, 3)})).collect(),
        Some((_, before, _)) => rooms_map::nsl_before_after(areas, before)
            .iter()
            .map(|c| {
                json!({"zone": c.now.zone, "points": c.now.points, "sees_sky": round(c.now.sees_sky, 3),
                    "sees_sky_before": c.before.map(|b| round(b, 3)), "ratio": c.ratio.map(|r| round(r, 4)), "passes": c.passes})
            })
            .collect(),
    };
    json!({
        "study": "bre-nsl",
        "source": "BRE 209 (3rd ed., 2022), the No-Sky Line: the share of a room's working plane that can see sky (a point sees sky when one of its sky sub-patch directions is clear)",
        "rule": former.map(|_| format!("with --before: a room passes when the share of its working plane that sees sky is not below {FORMER_RATIO} × its former value (rooms matched by zone name)")),
        "work_plane_m": args.work_plane.unwrap_or(NSL_WORK_PLANE),
        "sky_patches": patches.name(),
        "inputs": {"models": args.model.models, "before": (!args.before.is_empty()).then_some(&args.before)},
        "areas": rows,
    })
}

/// The scene and rooms of one EnergyPlus model given alone, or of mesh models whose rooms and
/// glass `--interior` and `--glazing` pick; `model` is the proposed model's or the existing one's.
fn read_rooms(args: &MapArgs, model: &ModelArgs) -> Result<(Scene, Rooms)> {
    if !args.interior.is_empty() {
        if args.glass_curve.is_some() {
            return Err(Error::argument(
                "--glass-curve",
                "is for an EnergyPlus model's glazing: a glTF pane's curve is its material's extras",
            ));
        }
        let mut loaded = model.load_rooms(&args.interior, &args.glazing)?;
        if let Some(ep) = &loaded.energyplus {
            return Err(Error::model(&ep.file, "--interior picks the rooms of mesh models: an EnergyPlus model's zones are its rooms"));
        }
        let rooms = gltf_rooms(&mut loaded.scene, &loaded.interior, &loaded.glazing, args.glass_transmittance)?;
        return Ok((loaded.scene, rooms));
    }
    let loaded = model.load_all(false)?;
    let Some(ep) = loaded.energyplus.as_ref().filter(|_| model.models.len() == 1) else {
        return Err(Error::argument(
            "inside",
            "maps the zones of one EnergyPlus model (IDF or epJSON), given alone, or the rooms --interior picks in mesh models",
        ));
    };
    Ok((inside_scene(ep)?, rooms_with(ep, &unread_glass(args)?)?))
}

/// What `--glass-transmittance` and `--glass-curve` give glazing whose construction sunlit cannot
/// read; a bad curve is refused naming the flag and why.
fn unread_glass(args: &MapArgs) -> Result<UnreadGlass> {
    let curve = args.glass_curve.as_deref().map(TransmittanceCurve::parse).transpose();
    let curve = curve.map_err(|why| Error::argument("--glass-curve", why))?;
    Ok(UnreadGlass { transmittance: args.glass_transmittance, curve })
}

/// One instant: the points' `lit` and glass weights, and each inside face's sun patch.
fn instant(
    scene: &Scene,
    map: InsideMap<'_>,
    period: &Period,
    location: &Location,
    calendar: &LeafCalendar,
    summary: &mut Value,
) -> (String, (&'static str, &'static str, Vec<f64>)) {
    let s = period.samples()[0];
    let sun = sunlit::sun::position::sun_direction(location, sunlit::year::annual::shading_sun_day(s.day), s.hour);
    let leaves = calendar.fraction(f64::from(s.day)) as f32;
    let (values, patches) = rooms_map::instant_with_patches(scene, map, sun, leaves);
    let columns = inside_instant_columns(&values);
    summary["sun_up"] = json!(sun.z >= sunlit::count::MIN_COS_INCIDENCE);
    summary["lit_points"] = json!(values.lit.iter().filter(|&&v| v >= 0.5).count());
    summary["sun_patches"] = json!(
        patches
            .iter()
            .map(|p| json!({"surface": p.surface, "zone": p.zone, "area_m2": round(p.area_m2, 6), "fraction": round(p.fraction, 6)}))
            .collect::<Vec<_>>()
    );
    (points_csv(scene, &map.at.points, &columns), ("lit", "", values.lit.clone()))
}

/// `POINTS.study-leed-ase.json`: the rule, its inputs and per room `zone`, `points` and `ase` (%).
fn ase_report(args: &MapArgs, location: &Location, result: &rooms_map::AseResult, at: &RoomPoints) -> Value {
    json!({
        "study": "leed-ase",
        "source": format!(
            "LEED v4.1 Annual Sunlight Exposure, IES LM-83-12 ASE{ASE_LUX:.0},{ASE_HOURS:.0}: share of the work plane with more than {ASE_HOURS:.0} occupied hours above {ASE_LUX:.0} lux of direct sun (blinds ignored)"
        ),
        "occupied": format!("{:02}:00-{:02}:00 local standard time, every day; no daylight saving shift", OCCUPIED.0 as u32, OCCUPIED.1 as u32),
        "occupied_hours": result.occupied,
        "illuminance": format!("EPW direct normal illuminance (field 18) × visible transmittance × cos incidence; {BEAM_EFFICACY} lm/W × direct normal irradiance for hours without it"),
        "efficacy_hours": result.efficacy_hours,
        "inputs": {
            "models": args.model.models,
            "points": args.points.as_ref().map_or(
                json!({"grid_spacing_m": args.grid.unwrap_or(ASE_SPACING), "work_plane_m": args.work_plane.unwrap_or(WORK_PLANE_HEIGHT)}),
                |p| json!({"file": p})
            ),
            "site": {"latitude": location.latitude, "longitude": location.longitude, "time_zone": location.time_zone},
        },
        "areas": result.areas.iter().map(|a| json!({"zone": a.zone, "points": a.points, "ase": round(a.ase, 3)})).collect::<Vec<_>>(),
        "point_count": at.points.len(),
    })
}
