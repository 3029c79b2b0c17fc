//! Sweeps: many variants of one annual run, read from a manifest (JSON Lines), counted locally
//! side by side or as a Slurm job array, resumable, with a merged summary.
//!
//! - [`manifest`]: the lines, checked all at once, each turned into an annual run's arguments;
//! - [`record`]: what the output folder remembers (done and failed records, logs);
//! - [`run`]: counting variants in child processes;
//! - [`summary`]: the per-surface means and `summary.csv`;
//! - [`slurm`]: the job array, its scripts and the merge job;
//! - [`district`]: a city model's tiles with their context, their records and the merged cadastre;
//! - [`district_year`]: a tile's year counted a batch of receivers at a time, and its stages;
//! - [`district_pv`]: with `--grid --pv`, what PV tools read for the roofs' points, per tile and merged;
//! - [`district_table`]: with `--year-table`, the receivers' whole-year tables, per tile and merged.
//!
//! Native only: it runs processes and writes files.

pub mod district;
pub mod district_pv;
pub mod district_table;
pub mod district_year;
pub mod manifest;
pub mod record;
pub mod run;
pub mod slurm;
pub mod summary;

use std::path::Path;

pub use manifest::{Manifest, OptionKind, OptionSpec, Problem, Schema, Variant};

use crate::error::{Error, Result};
use crate::export::write_atomic;

/// The file listing failed variants in the output folder (absent when none failed).
pub const FAILED_CSV: &str = "failed.csv";

/// The variants task `index` runs when each task takes `per_task` of them: the index-th run of
/// `per_task` consecutive variants in manifest order.
pub fn chunk(variants: &[Variant], index: usize, per_task: usize) -> Result<Vec<&Variant>> {
    if per_task == 0 {
        return Err(Error::argument("per_task", "must be at least 1"));
    }
    let tasks = variants.len().div_ceil(per_task);
    if index >= tasks {
        return Err(Error::argument(
            "index",
            format!("{index} is past the last task ({} variants, {per_task} a task: 0..={})", variants.len(), tasks.saturating_sub(1)),
        ));
    }
    Ok(variants.iter().skip(index * per_task).take(per_task).collect())
}

/// A variant that is not finished, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Unfinished {
    /// The variant's id.
    pub id: String,
    /// Its annual run's exit code, when it ran and failed with one.
    pub exit_code: Option<i32>,
    /// What happened.
    pub reason: String,
}

/// What a merge found.
#[derive(Debug, Clone, Default)]
pub struct Merged {
    /// Finished variants (in the summary).
    pub finished: usize,
    /// Variants without a valid done record.
    pub unfinished: Vec<Unfinished>,
}

/// Writes `summary.csv` from the finished variants' records, and `failed.csv` listing the rest
/// with their exit codes (removed when every variant is finished).
pub fn merge(manifest: &Manifest, dir: &Path) -> Result<Merged> {
    let mut finished = Vec::new();
    let mut unfinished = Vec::new();
    for v in &manifest.variants {
        match record::finished(dir, v) {
            Some(done) => finished.push((v, done)),
            None => {
                let (exit_code, reason) = match record::failure(dir, &v.id) {
                    Some(f) => (f.exit_code, f.reason),
                    None => (None, "no record: not run yet, or stopped (cancelled, killed) before it finished".to_string()),
                };
                unfinished.push(Unfinished { id: v.id.clone(), exit_code, reason });
            }
        }
    }
    let rows: Vec<(&Variant, &record::Done)> = finished.iter().map(|(v, d)| (*v, d)).collect();
    write_atomic(&dir.join(summary::SUMMARY), summary::summary_csv(&rows).as_bytes())?;
    let failed = dir.join(FAILED_CSV);
    if unfinished.is_empty() {
        let _ = std::fs::remove_file(&failed);
    } else {
        let mut text = String::from("id,exit_code,reason\n");
        for u in &unfinished {
            let code = u.exit_code.map(|c| c.to_string()).unwrap_or_default();
            text.push_str(&format!("{},{code},\"{}\"\n", u.id, u.reason.replace('"', "\"\"")));
        }
        write_atomic(&failed, text.as_bytes())?;
    }
    Ok(Merged { finished: finished.len(), unfinished })
}
