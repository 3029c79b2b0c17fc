//! `sunlit map --pvlib`, `--sam`: what PV tools read for a map's points (a grid on roofs or
//! façades, or points from a CSV), as `annual --pvlib`, `--sam` write it for surfaces. The
//! library owns the series ([`sunlit::map::series`]) and the layouts ([`sunlit::export::pv`]).

use std::path::PathBuf;

use sunlit::export::pv::{self, PvSet, SamInputs};
use sunlit::map::{MapValues, Mapper, Period, Points, Sample, Site};

use super::progress::Meter;
use super::{MapArgs, Plan};
use crate::{Error, Result, check_writable};

/// Whether either PV output is asked for.
pub(super) fn wanted(args: &MapArgs) -> bool {
    args.pvlib.is_some() || args.sam.is_some()
}

/// Refuses what the PV outputs cannot be made from, before the model is read: a period other
/// than the whole year, the GPU's masks, SAM without weather, a path that cannot be written.
pub(super) fn check(args: &MapArgs, plan: &Plan, on_gpu: bool) -> Result<()> {
    let flag = if args.pvlib.is_some() { "pvlib" } else { "sam" };
    if !wanted(args) {
        return Ok(());
    }
    if plan.instant || !matches!(plan.period, Period::Days { first: 1, last: sunlit::year::samples::DAYS, .. }) || !plan.rules.is_empty() {
        return Err(Error::argument(flag, "covers a whole year: give --period annual (the default) and no --at or --study"));
    }
    if on_gpu {
        return Err(Error::argument(flag, "is counted by shadow rays: give --engine exact or auto"));
    }
    if args.sam.is_some() && args.epw.is_none() {
        return Err(Error::argument("sam", "needs a weather file (--epw) for the diffuse loss"));
    }
    for path in args.pvlib.iter().chain(&args.sam) {
        check_writable(path)?;
    }
    Ok(())
}

/// The PV files and their bytes, from the points' series over the year (`samples`, at `per_hour`
/// timesteps) and their sums `values` (the shaded sky diffuse SAM's loss is made of).
pub(super) fn outputs(
    args: &MapArgs,
    mapper: &Mapper,
    points: &Points,
    samples: &[Sample],
    site: Site<'_>,
    values: &MapValues,
    meter: &mut Meter,
) -> Result<Vec<(PathBuf, Vec<u8>)>> {
    let per_hour = (samples.len() / (24 * sunlit::year::samples::DAYS as usize)).max(1) as u32;
    meter.stage(&format!("{} points: PV series", points.len()), "instants");
    let series = mapper.visibility_series(samples, site, &mut meter.counts())?;
    let set = PvSet::points(points, &series, per_hour)?;
    let year = pv::DEFAULT_YEAR;
    let mut out = Vec::new();
    if let Some(path) = &args.pvlib {
        out.push((path.clone(), pv::pvlib_csv(&set, site.location, year)?));
    }
    if let Some(path) = &args.sam {
        meter.stage(&format!("{} points: SAM's azimuth × altitude table", points.len()), "directions");
        let directions: Vec<_> = pv::azal_directions().into_iter().map(|d| d.2).collect();
        let azal_fractions = mapper.direction_visibility(&directions);
        let shaded = values.sky_diffuse_kwh_m2.as_ref().ok_or_else(|| Error::argument("sam", "needs the points' sky (--epw)"))?;
        let unshaded = mapper.unshaded_sky_diffuse(samples, site)?;
        let diffuse = pv::diffuse_sums(set.areas.iter().zip(shaded).zip(&unshaded).map(|((&a, &s), &u)| (a, s, u)));
        out.push((path.clone(), pv::sam_json(&set, site.location, &SamInputs { year, azal_fractions: &azal_fractions, diffuse })?));
    }
    Ok(out)
}
