//! What the tests of the sun inside share: the numpy reference (tests/inside/reference.py, written
//! independently of sunlit) and the Golden EPW that EnergyPlus's wheel ships.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use serde_json::Value;

/// numpy's Python: `SUNLIT_RADIANCE_PYTHON`, else the .venv-rad that `npm test` sets up.
pub fn python() -> PathBuf {
    if let Some(p) = std::env::var_os("SUNLIT_RADIANCE_PYTHON") {
        return PathBuf::from(p);
    }
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv-rad/bin/python");
    assert!(
        venv.exists(),
        "numpy's Python not found: run `SUNLIT_RADIANCE=1 . scripts/setup.sh` (npm test does) or set SUNLIT_RADIANCE_PYTHON"
    );
    venv
}

/// tests/inside/reference.py's answer to `query` (JSON on stdin and stdout).
pub fn numpy_reference(query: &Value) -> Value {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/inside/reference.py");
    let mut child = Command::new(python()).arg(script).stdin(Stdio::piped()).stdout(Stdio::piped()).spawn().unwrap();
    child.stdin.take().unwrap().write_all(query.to_string().as_bytes()).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "reference.py failed");
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Golden, Colorado's TMY3 weather, beside the EnergyPlus binary.
pub fn golden_epw() -> PathBuf {
    let epw = super::energyplus::energyplus().parent().unwrap().join("WeatherData/USA_CO_Golden-NREL.724666_TMY3.epw");
    assert!(epw.exists(), "{} missing", epw.display());
    epw
}
