//! `sunlit annual`'s solar outputs: the per-surface summary (`--summary`), the per-timestep
//! irradiance (`--irradiance`) and what PV tools read (`--pvlib`, `--sam`), with their flags
//! `--albedo`, `--sky-patches` and `--sky-model`.
//!
//! A thin edge like the rest of the CLI: it reads the flags and the weather before any counting
//! (so a bad value is refused with nothing written), then asks the library for the sky views
//! (same engine as the fractions), EnergyPlus's ratios (on the EnergyPlus model's own casters
//! when a glTF context is loaded beside it) and the texts, which `annual` writes with its CSV.

use std::path::PathBuf;

use sunlit::count::hybrid::HybridEngine;
use sunlit::export::Schedule;
use sunlit::export::irradiation::{self, EnergyPlusRatios, Solar};
use sunlit::export::pv;
use sunlit::model;
use sunlit::scene::Scene;
use sunlit::sky::directions::direction_fractions;
use sunlit::sky::model::SkyModel;
use sunlit::sky::patches::SkyPatches;
use sunlit::sky::views::sky_views_for;
use sunlit::sun::weather::{Weather, check_albedo};
use sunlit::year::annual::Progress;
use sunlit::year::settings::Resolved;
use sunlit::{Error, Result};

use super::progress::Meter;
use super::{AnnualArgs, check_writable};

/// Writes a summary as JSON or CSV.
type SummaryFormat = fn(&[irradiation::SurfaceSummary]) -> String;

/// What the solar outputs need, read and checked before the counting.
pub struct SolarPlan {
    patches: SkyPatches,
    model: SkyModel,
    weather: Option<Weather>,
    summary: Option<(PathBuf, SummaryFormat)>,
    irradiance: Option<PathBuf>,
    pvlib: Option<PathBuf>,
    sam: Option<PathBuf>,
    /// The run's year once chosen (labels the PV outputs' time index).
    pub year: Option<i32>,
}

/// `--summary`'s and `--irradiance`'s files, the patch scheme, and the EPW's solar data (read
/// now, so a bad weather file, albedo or scheme is refused before the counting). `None` when
/// neither output is asked for.
pub fn solar_plan(args: &AnnualArgs) -> Result<Option<SolarPlan>> {
    let patches = SkyPatches::parse(args.sky_patches.as_deref().unwrap_or("tregenza"))?;
    let model = args.sky_model.as_deref().map_or(Ok(SkyModel::EnergyPlus), SkyModel::parse)?;
    if args.sky_model.is_some() && args.epw.is_none() {
        return Err(Error::argument("sky_model", "needs a weather file (--epw): the sky's light comes from it"));
    }
    if let Some(albedo) = args.albedo {
        check_albedo(albedo)?;
    }
    let summary = match &args.summary {
        Some(path) => {
            let extension = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
            let format: SummaryFormat = match extension.as_deref() {
                Some("json") => irradiation::summary_json,
                Some("csv") => irradiation::summary_csv,
                _ => return Err(Error::argument("summary", format!("{}: give a .json or .csv file", path.display()))),
            };
            check_writable(path)?;
            Some((path.clone(), format))
        }
        None => None,
    };
    if let Some(path) = &args.irradiance {
        if args.epw.is_none() {
            return Err(Error::argument("irradiance", "needs a weather file (--epw) for its irradiance"));
        }
        check_writable(path)?;
    }
    if let Some(path) = &args.pvlib {
        check_writable(path)?;
    }
    if let Some(path) = &args.sam {
        if args.epw.is_none() {
            return Err(Error::argument("sam", "needs a weather file (--epw) for the diffuse loss"));
        }
        check_writable(path)?;
    }
    if summary.is_none() && args.irradiance.is_none() && args.pvlib.is_none() && args.sam.is_none() {
        return Ok(None);
    }
    let weather = match &args.epw {
        Some(path) => {
            let weather = Weather::from_epw(path)?;
            Some(match args.albedo {
                Some(albedo) => weather.with_albedo(albedo)?,
                None => weather,
            })
        }
        None => None,
    };
    Ok(Some(SolarPlan {
        patches,
        model,
        weather,
        summary,
        irradiance: args.irradiance.clone(),
        pvlib: args.pvlib.clone(),
        sam: args.sam.clone(),
        year: None,
    }))
}

/// The files the plan writes and their bytes, made before anything is written.
pub fn solar_outputs(
    plan: &SolarPlan,
    engine: &HybridEngine<'_>,
    scene: &Scene,
    settings: &Resolved,
    schedule: &Schedule,
    args: &AnnualArgs,
    meter: &mut Meter,
) -> Result<Vec<(PathBuf, Vec<u8>)>> {
    let year = plan.year.unwrap_or(pv::DEFAULT_YEAR);
    let mut out = Vec::new();
    if let Some(path) = &plan.pvlib {
        out.push((path.clone(), pv::pvlib_csv(&pv::PvSet::surfaces(scene, schedule)?, &settings.location, year)?));
    }
    // The pvlib CSV needs the fractions alone, not the sky.
    if plan.summary.is_none() && plan.irradiance.is_none() && plan.sam.is_none() {
        return Ok(out);
    }
    let start = std::time::Instant::now();
    meter.stage("sky views", "views");
    let views = pollster::block_on(sky_views_for(engine, scene, &plan.patches, plan.model, &mut |p| {
        meter.report(p);
        Ok(())
    }))?;
    eprintln!(
        "sky views: {} receivers × {} patches ({}, {} sky) in {:.2} s",
        scene.receivers.len(),
        plan.patches.len(),
        plan.patches.name(),
        plan.model.name(),
        start.elapsed().as_secs_f64()
    );
    if let (Some(path), Some(weather)) = (&plan.irradiance, &plan.weather) {
        let solar = Solar { weather, sky: &views, calendar: &settings.calendar };
        out.push((path.clone(), irradiation::irradiance_csv(scene, schedule, &settings.location, &solar)?));
    }
    if let (Some(path), Some(weather)) = (&plan.sam, &plan.weather) {
        meter.stage("SAM's azimuth × altitude table", "views");
        let directions: Vec<_> = pv::azal_directions().into_iter().map(|d| d.2).collect();
        let azal_fractions = pollster::block_on(direction_fractions(engine, scene, &directions, &mut |p| {
            meter.report(p);
            Ok(())
        }))?;
        let summaries =
            irradiation::summarize(scene, schedule, &settings.location, Some((&views, &settings.calendar)), Some(weather), &[])?;
        let inputs = pv::SamInputs { year, azal_fractions: &azal_fractions, diffuse: pv::surfaces_diffuse_sums(&summaries)? };
        out.push((path.clone(), pv::sam_json(&pv::PvSet::surfaces(scene, schedule)?, &settings.location, &inputs)?));
    }
    if let Some((path, format)) = &plan.summary {
        let start = std::time::Instant::now();
        meter.stage("EnergyPlus's diffuse ratios", "views");
        let ratios = energyplus_ratios(engine, scene, args, &mut |p| {
            meter.report(p);
            Ok(())
        })?;
        eprintln!("EnergyPlus's diffuse shading ratios (144 directions) in {:.2} s", start.elapsed().as_secs_f64());
        let summaries = irradiation::summarize(
            scene,
            schedule,
            &settings.location,
            Some((&views, &settings.calendar)),
            plan.weather.as_ref(),
            &ratios,
        )?;
        out.push((path.clone(), format(&summaries).into_bytes()));
    }
    Ok(out)
}

/// EnergyPlus's ratios per receiver of `scene`, from the casters EnergyPlus sees: with an
/// EnergyPlus model and other model files, a scene of the EnergyPlus model alone (a receiver it
/// does not have gets `None`); otherwise `scene` itself.
fn energyplus_ratios(
    engine: &HybridEngine<'_>,
    scene: &Scene,
    args: &AnnualArgs,
    report: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<Vec<Option<EnergyPlusRatios>>> {
    let models = &args.model.models;
    let energyplus: Vec<PathBuf> = models.iter().filter(|p| model::is_energyplus_file(&p.display().to_string())).cloned().collect();
    if energyplus.is_empty() || energyplus.len() == models.len() {
        let ratios = pollster::block_on(sunlit::sky::energyplus::ratios(engine, scene, report))?;
        return Ok(ratios.into_iter().map(Some).collect());
    }
    let own = match model::load(&energyplus, &args.model.options()) {
        Ok(own) => own,
        Err(Error::NoReceivers(_)) => return Ok(vec![None; scene.receivers.len()]),
        Err(e) => return Err(e),
    };
    let own_engine = HybridEngine::new(&own, args.engine.kind()?, args.pixels.options(), args.lanes, args.engine.source())?;
    let ratios = pollster::block_on(sunlit::sky::energyplus::ratios(&own_engine, &own, report))?;
    Ok(scene.receivers.iter().map(|r| own.receivers.iter().position(|o| o.name.eq_ignore_ascii_case(&r.name)).map(|i| ratios[i])).collect())
}
