//! What a sweep remembers in its output folder, so a second run (or another Slurm task) knows
//! what is finished: `.done/<id>.json` per finished variant, `.failed/<id>.json` per failed one.
//!
//! A done record holds the variant's fingerprint (its arguments, the input files' sizes and
//! modification times, and sunlit's version) and the summary of its CSV. A variant is finished
//! when its record's fingerprint equals the current one and its outputs exist; a changed line,
//! input file or version is counted again. Records are written atomically after the outputs, so
//! a run killed in between counts that variant again, never trusts a half-written one.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::manifest::Variant;
use crate::error::{Error, Result};
use crate::export::write_atomic;

/// Folder of done records inside the output folder.
pub const DONE: &str = ".done";
/// Folder of failure records inside the output folder.
pub const FAILED: &str = ".failed";
/// Folder of the annual runs' logs inside the output folder.
pub const LOGS: &str = ".logs";

/// What a variant's outputs were made from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fingerprint {
    /// sunlit's version.
    pub version: String,
    /// The annual run's arguments (without the output folder).
    pub args: Vec<String>,
    /// Each input file: path, size in bytes, modification time (seconds since 1970).
    pub inputs: Vec<(String, u64, u64)>,
}

impl Fingerprint {
    /// The fingerprint of `variant` now (input files that cannot be read count as size 0).
    pub fn of(variant: &Variant) -> Self {
        Self::new(variant.args.clone(), &variant.inputs)
    }

    /// The fingerprint of a run with `args` reading `inputs`, now.
    pub fn new(args: Vec<String>, inputs: &[PathBuf]) -> Self {
        let inputs = inputs
            .iter()
            .map(|p| {
                let meta = std::fs::metadata(p).ok();
                let modified = meta
                    .as_ref()
                    .and_then(|m| m.modified().ok())
                    .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
                    .map_or(0, |d| d.as_secs());
                (p.display().to_string(), meta.map_or(0, |m| m.len()), modified)
            })
            .collect();
        Self { version: env!("CARGO_PKG_VERSION").to_string(), args, inputs }
    }

    /// A short hash of the fingerprint (64-bit FNV-1a of its JSON), for logs and the summary.
    pub fn hash(&self) -> String {
        let text = serde_json::to_string(self).unwrap_or_default();
        let h = text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3));
        format!("{h:016x}")
    }
}

/// A surface's mean over its variant's year.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfaceMean {
    /// The surface (CSV column).
    pub surface: String,
    /// Mean sunlit fraction over the sun-up timesteps.
    pub mean_fraction: f64,
    /// Sun-up timesteps of the year.
    pub sunup_timesteps: usize,
    /// Annual direct irradiation Σ DNI·cos θ·fraction·Δt, kWh/m² (a variant with an EPW).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub irradiation: Option<f64>,
    /// The same unshaded, kWh/m².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unshaded_irradiation: Option<f64>,
    /// The rest of the annual summary's split ([`SOLAR_KEYS`]), where the run wrote it.
    #[serde(default, skip_serializing_if = "Solar::is_empty")]
    pub solar: Solar,
}

/// The annual summary's keys beside the direct irradiation, in summary.csv's column order.
pub const SOLAR_KEYS: [&str; 7] = [
    "sky_diffuse",
    "ground_reflected",
    "total",
    "unshaded_total",
    "sky_view_factor",
    "energyplus_iso_sky_ratio",
    "energyplus_horizon_ratio",
];

/// A surface's values for [`SOLAR_KEYS`] (kWh/m² for the first four, ratios for the rest).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Solar(pub Vec<Option<f64>>);

impl Solar {
    /// Nothing was read.
    pub fn is_empty(&self) -> bool {
        self.0.iter().all(Option::is_none)
    }
}

/// The record of a finished variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Done {
    /// The variant's id.
    pub id: String,
    /// What it was made from.
    pub fingerprint: Fingerprint,
    /// [`Fingerprint::hash`].
    pub hash: String,
    /// Output file names (in the output folder).
    pub outputs: Vec<String>,
    /// Seconds the annual run took.
    pub seconds: f64,
    /// Per surface, the mean over sun-up timesteps.
    pub surfaces: Vec<SurfaceMean>,
}

/// The record of a failed variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Failed {
    /// The variant's id.
    pub id: String,
    /// The annual run's exit code (`None` when a signal ended it).
    pub exit_code: Option<i32>,
    /// What went wrong, in a line.
    pub reason: String,
    /// The run's log (in the output folder).
    pub log: String,
}

/// The done record's path for `id`.
pub fn done_path(dir: &Path, id: &str) -> PathBuf {
    dir.join(DONE).join(format!("{id}.json"))
}

/// The failure record's path for `id`.
pub fn failed_path(dir: &Path, id: &str) -> PathBuf {
    dir.join(FAILED).join(format!("{id}.json"))
}

/// The annual run's log path for `id`.
pub fn log_path(dir: &Path, id: &str) -> PathBuf {
    dir.join(LOGS).join(format!("{id}.log"))
}

/// Makes the output folder and its record folders.
pub fn prepare(dir: &Path) -> Result<()> {
    for sub in [DONE, FAILED, LOGS] {
        let path = dir.join(sub);
        std::fs::create_dir_all(&path).map_err(|source| Error::Io { path, source })?;
    }
    Ok(())
}

/// The done record of `variant` if it is finished: the record's fingerprint is today's and its
/// outputs are all there.
pub fn finished(dir: &Path, variant: &Variant) -> Option<Done> {
    let text = std::fs::read_to_string(done_path(dir, &variant.id)).ok()?;
    let done: Done = serde_json::from_str(&text).ok()?;
    let complete = done.fingerprint == Fingerprint::of(variant) && variant.outputs(dir).iter().all(|p| p.is_file());
    complete.then_some(done)
}

/// Writes `done` (atomically) and clears a failure record of the same id.
pub fn write_done(dir: &Path, done: &Done) -> Result<()> {
    let path = done_path(dir, &done.id);
    let text = serde_json::to_vec_pretty(done).map_err(|e| Error::model(path.display().to_string(), e.to_string()))?;
    write_atomic(&path, &text)?;
    let _ = std::fs::remove_file(failed_path(dir, &done.id));
    Ok(())
}

/// Writes `failed` (atomically).
pub fn write_failed(dir: &Path, failed: &Failed) -> Result<()> {
    let path = failed_path(dir, &failed.id);
    let text = serde_json::to_vec_pretty(failed).map_err(|e| Error::model(path.display().to_string(), e.to_string()))?;
    write_atomic(&path, &text)
}

/// The failure record of `id`, if there is one.
pub fn failure(dir: &Path, id: &str) -> Option<Failed> {
    serde_json::from_str(&std::fs::read_to_string(failed_path(dir, id)).ok()?).ok()
}

/// Forgets a variant before it is counted again: its old record must not vouch for the new
/// outputs if this run is killed halfway.
pub fn forget(dir: &Path, id: &str) {
    let _ = std::fs::remove_file(done_path(dir, id));
}
