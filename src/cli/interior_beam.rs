//! `sunlit annual --interior-beam`: the beam through exterior windows onto their zones' inside
//! faces, handed to EnergyPlus beside the sunlit fractions. A thin edge: it refuses what cannot
//! be hooked before any counting, then asks the library for the beam
//! ([`sunlit::year::interior_beam`]) and the objects ([`sunlit::export::hook`]).

use std::path::{Path, PathBuf};

use sunlit::export::hook::Hook;
use sunlit::export::interior_beam::{interior_beam_csv, interior_beam_objects};
use sunlit::model::EnergyPlusInput;
use sunlit::model::inside::curve::TransmittanceCurve;
use sunlit::model::inside::{Rooms, UnreadGlass, rooms_with};
use sunlit::sun::location::Location;
use sunlit::sun::periods::ShadingPeriods;
use sunlit::sun::weather::Weather;
use sunlit::year::interior_beam::interior_beam;
use sunlit::year::samples::Timesteps;
use sunlit::{Error, Result};

use super::AnnualArgs;

/// What the interior beam needs, read and checked before the counting.
pub struct BeamPlan {
    /// The model's zones and windows.
    rooms: Rooms,
    /// The weather's DNI.
    weather: Weather,
    /// Where the CSV goes (beside the sunlit fraction CSV).
    pub csv: PathBuf,
}

/// The CSV beside `output`: `NAME.interior-beam.csv` for `NAME.csv`.
fn csv_path(output: &Path) -> PathBuf {
    let stem = output.file_stem().map_or_else(|| "sunlit".into(), |s| s.to_string_lossy().into_owned());
    output.with_file_name(format!("{stem}.interior-beam.csv"))
}

/// None without `--interior-beam`; otherwise the plan, or a refusal naming the flag and why.
pub fn beam_plan(args: &AnnualArgs, hook: Option<Hook>, ep: Option<&EnergyPlusInput>) -> Result<Option<BeamPlan>> {
    if !args.interior_beam {
        return Ok(None);
    }
    let refuse = |why: &str| Err(Error::argument("--interior-beam", why.to_string()));
    if args.idf_out.is_none() {
        return refuse("hands the beam to EnergyPlus: add --idf-out");
    }
    if hook == Some(Hook::Imported) {
        return refuse("is written beside the Scheduled hook (EnergyPlus 25.2 ignores the Imported one)");
    }
    let Some(epw) = &args.epw else { return refuse("needs --epw: the beam is the weather's direct normal irradiance") };
    let Some(ep) = ep else { return refuse("needs an EnergyPlus model among the inputs") };
    if ep.epjson {
        return refuse("writes IDF objects: give the model as .idf");
    }
    if let Some(o) = ep.objects.iter().find(|o| o.is("SurfaceProperty:SolarIncidentInside")) {
        return Err(Error::object(&ep.file, o.label(), "the model has inside solar schedules of its own; sunlit would add its own"));
    }
    let csv = csv_path(&args.output);
    super::check_writable(&csv)?;
    let curve = args.glass_curve.as_deref().map(TransmittanceCurve::parse).transpose();
    let curve = curve.map_err(|why| Error::argument("--glass-curve", why))?;
    let glass = UnreadGlass { transmittance: args.glass_transmittance, curve };
    Ok(Some(BeamPlan { rooms: rooms_with(ep, &glass)?, weather: Weather::from_epw(epw)?, csv }))
}

/// The CSV's bytes and the objects to append to the hooked model, with the notes to print.
pub fn beam_outputs(
    plan: &BeamPlan,
    ep: &EnergyPlusInput,
    location: &Location,
    timesteps: Timesteps,
    periods: Option<ShadingPeriods>,
) -> Result<(Vec<u8>, String, Vec<String>)> {
    let beam = interior_beam(ep, &plan.rooms, &plan.weather, location, timesteps, periods)?;
    let folder = std::fs::canonicalize(plan.csv.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new(".")))
        .map_err(|source| Error::Io { path: plan.csv.clone(), source })?;
    let name = folder.join(plan.csv.file_name().unwrap_or_default()).display().to_string();
    if name.contains([',', ';', '!']) {
        return Err(Error::argument("--output", format!("'{name}': an IDF field cannot hold ',', ';' or '!'; choose a path without them")));
    }
    let mut notes = vec![format!(
        "interior beam: {} inside faces of {} zones, {} views; each zone's balance rides on one exterior window ({})",
        beam.faces.len(),
        beam.balances.len(),
        beam.views,
        beam.balances.iter().map(|b| b.window.as_str()).collect::<Vec<_>>().join(", ")
    )];
    if !beam.skipped.is_empty() {
        notes.push(format!("interior beam: interzone windows skipped (no exterior beam of their own): {}", beam.skipped.join(", ")));
    }
    notes.push(
        "interior beam: the schedules tie the hooked model to this weather file. Design days and sizing periods read \
         them too: this EPW's beam for the same calendar day replaces EnergyPlus's own on every hooked face there, so \
         size with the original model"
            .to_string(),
    );
    Ok((interior_beam_csv(&beam, timesteps).into_bytes(), interior_beam_objects(&name, &beam, timesteps), notes))
}
