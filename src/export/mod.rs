//! Export: the annual sunlit-fraction schedule as the CSV EnergyPlus reads.
//!
//! Owns the file format and its safety. The layout is EnergyPlus's own eplusshading.csv (what
//! `Schedule:File:Shading` reads): a header `Surface Name,NAME1,NAME2,…,` then one row per
//! timestep ` MM/DD HH:MM,v1,v2,…,` with 8 decimals and a trailing comma, exactly 8760·N rows.
//! A schedule is checked before anything is written (row count, names, values in [0, 1]), and
//! files are written to a temporary sibling and renamed, so a failure never leaves a partial file.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::samples::Timesteps;

pub mod hook;

/// Sunlit fractions of named surfaces at every timestep of a year.
#[derive(Debug, Clone, PartialEq)]
pub struct Schedule {
    /// Column names (surface names as EnergyPlus knows them).
    pub names: Vec<String>,
    /// Timesteps per hour.
    pub timesteps: Timesteps,
    /// Row-major values: `values[row * names.len() + column]`.
    pub values: Vec<f32>,
}

impl Schedule {
    /// A schedule of zeros.
    pub fn zeros(names: Vec<String>, timesteps: Timesteps) -> Self {
        let values = vec![0.0; timesteps.rows() * names.len()];
        Self { names, timesteps, values }
    }

    /// Value of `column` at `row`.
    pub fn get(&self, row: usize, column: usize) -> f32 {
        self.values[row * self.names.len() + column]
    }

    /// Sets the value of `column` at `row`.
    pub fn set(&mut self, row: usize, column: usize, value: f32) {
        let n = self.names.len();
        self.values[row * n + column] = value;
    }

    /// Checks what EnergyPlus would reject or misread.
    pub fn validate(&self) -> Result<()> {
        let bad = |reason: String| Error::argument("schedule", reason);
        if self.names.is_empty() {
            return Err(bad("no surfaces".into()));
        }
        if self.values.len() != self.timesteps.rows() * self.names.len() {
            return Err(bad(format!("{} values for {} rows × {} surfaces", self.values.len(), self.timesteps.rows(), self.names.len())));
        }
        let mut seen = std::collections::HashSet::new();
        for name in &self.names {
            if name.is_empty() || name.contains([',', '\n', '\r', '"']) {
                return Err(bad(format!("surface name '{name}' cannot be a CSV column (empty, or holds a comma, quote or newline)")));
            }
            if !seen.insert(name.to_uppercase()) {
                return Err(bad(format!("surface name '{name}' appears twice (EnergyPlus names are case-insensitive)")));
            }
        }
        if let Some(i) = self.values.iter().position(|v| !(0.0..=1.0).contains(v)) {
            let (row, col) = (i / self.names.len(), i % self.names.len());
            return Err(bad(format!("value {} for '{}' at row {row} is outside [0, 1]", self.values[i], self.names[col])));
        }
        Ok(())
    }

    /// The CSV's bytes (after [`Self::validate`]).
    pub fn csv_bytes(&self) -> Result<Vec<u8>> {
        self.validate()?;
        let mut text = Vec::with_capacity(self.timesteps.rows() * (14 + 11 * self.names.len()));
        text.extend_from_slice(b"Surface Name,");
        for name in &self.names {
            text.extend_from_slice(name.as_bytes());
            text.push(b',');
        }
        text.push(b'\n');
        for (row, values) in self.values.chunks_exact(self.names.len()).enumerate() {
            text.extend_from_slice(self.timesteps.stamp(row).as_bytes());
            for v in values {
                // Values are f32 internally; print the f64 of the rounded f32 to 8 decimals.
                let _ = write!(text, ",{:.8}", *v as f64);
            }
            text.extend_from_slice(b",\n");
        }
        Ok(text)
    }

    /// The CSV as a string.
    pub fn to_csv(&self) -> Result<String> {
        String::from_utf8(self.csv_bytes()?).map_err(|e| Error::argument("schedule", e.to_string()))
    }
}

/// Writes `bytes` to `path` atomically: a temporary file beside it, flushed, then renamed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let io = |source: std::io::Error, p: &Path| Error::Io { path: p.to_path_buf(), source };
    let tmp = temporary_sibling(path);
    let result = (|| {
        let mut file = std::fs::File::create(&tmp).map_err(|e| io(e, path))?;
        file.write_all(bytes).map_err(|e| io(e, path))?;
        file.sync_all().map_err(|e| io(e, path))?;
        std::fs::rename(&tmp, path).map_err(|e| io(e, path))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

fn temporary_sibling(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.partial", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn schedule() -> Schedule {
        let mut s = Schedule::zeros(vec!["WALL_S".into(), "WIN_S".into()], Timesteps::new(4).unwrap());
        s.set(50, 1, 0.125);
        s
    }

    #[test]
    fn csv_has_energyplus_layout() {
        let text = schedule().to_csv().unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 1 + 35_040);
        assert_eq!(lines[0], "Surface Name,WALL_S,WIN_S,");
        assert_eq!(lines[1], " 01/01 00:15,0.00000000,0.00000000,");
        assert_eq!(lines[51], " 01/01 12:45,0.00000000,0.12500000,");
        assert_eq!(*lines.last().unwrap(), " 12/31 24:00,0.00000000,0.00000000,");
    }

    #[test]
    fn invalid_schedules_are_never_written() {
        let dir = std::env::temp_dir().join(format!("sunlit-export-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.csv");
        let mut s = schedule();
        s.set(3, 0, 1.5);
        assert!(s.to_csv().unwrap_err().to_string().contains("outside [0, 1]"));
        let mut s = schedule();
        s.values.pop();
        assert!(s.validate().is_err());
        let mut s = schedule();
        s.names[1] = "wall_s".into();
        assert!(s.validate().unwrap_err().to_string().contains("twice"));
        let mut s = schedule();
        s.names[0] = "A,B".into();
        assert!(s.validate().is_err());
        assert!(!path.exists());
    }

    #[test]
    fn atomic_write_replaces_or_leaves_nothing() {
        let dir = std::env::temp_dir().join(format!("sunlit-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.csv");
        write_atomic(&path, b"one").unwrap();
        write_atomic(&path, b"two").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
        let missing = dir.join("no/such/dir/a.csv");
        let e = write_atomic(&missing, b"x").unwrap_err().to_string();
        assert!(e.contains("no/such/dir/a.csv"), "{e}");
        let leftovers: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".partial"))
            .collect();
        assert!(leftovers.is_empty());
    }
}
