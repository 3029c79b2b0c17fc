//! Export: the annual sunlit-fraction schedule as the CSV EnergyPlus reads.
//!
//! Owns the file format and its safety. The layout is EnergyPlus's own eplusshading.csv (what
//! `Schedule:File:Shading` reads): a header `Surface Name,NAME1,NAME2,…,` then one row per
//! timestep ` MM/DD HH:MM,v1,v2,…,` with 8 decimals and a trailing comma, exactly 8760·N rows.
//! A schedule is checked before anything is written (row count, names, values in [0, 1]), and
//! files are written to a temporary sibling and renamed, so a failure never leaves a partial file
//! (a device or pipe given as the output is written through instead: a rename would replace it).
//! Beside it, [`hook`] patches an EnergyPlus model to read the CSV, and [`interior_beam`] writes
//! the beam onto inside faces that a hooked model reads too.

use std::io::Write;
use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::error::{Error, Result};
use crate::sun::location::Location;
use crate::sun::periods::ShadingPeriods;
use crate::year::annual::shaded_sun;
use crate::year::samples::Timesteps;

pub mod cadastre;
pub mod cadastre_points;
pub mod glitches;
pub mod hook;
pub mod interior_beam;
pub mod irradiation;
pub mod map_glb;
pub mod map_table;
pub mod planning_report;
pub mod planning_tables;
pub mod pv;
pub mod wgs84;

/// Sunlit fractions of named surfaces at every timestep of a year.
#[derive(Debug, Clone, PartialEq)]
pub struct Schedule {
    /// Column names (surface names as EnergyPlus knows them).
    pub names: Vec<String>,
    /// Timesteps per hour.
    pub timesteps: Timesteps,
    /// Row-major values: `values[row * names.len() + column]`.
    pub values: Vec<f32>,
    /// The EnergyPlus `Periodic` update the fractions were counted for (every day of a period
    /// one sun, [`ShadingPeriods`]); `None`: each calendar day's own sun. Passes that weigh the
    /// fractions by the sun's incidence take it from [`Self::fraction_sun`].
    pub periods: Option<ShadingPeriods>,
}

impl Schedule {
    /// A schedule of zeros.
    pub fn zeros(names: Vec<String>, timesteps: Timesteps) -> Self {
        let values = vec![0.0; timesteps.rows() * names.len()];
        Self { names, timesteps, values, periods: None }
    }

    /// The sun the fractions of `row` were counted for: the period's mean sun under a `Periodic`
    /// update, else the calendar day's ([`shading_sun_day`]). EnergyPlus weighs its beam by the
    /// incidence of the sun it shaded for (`CosIncAng` beside `SunlitFrac`, both from
    /// `CalcPerSolarBeam`), while the weather's own sun (`SOLCOS`) decides whether the sun is up
    /// and places the circumsolar sky.
    pub fn fraction_sun(&self, location: &Location, row: usize) -> DVec3 {
        shaded_sun(location, self.timesteps, self.periods, row)
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
            for &v in values {
                text.push(b',');
                push_fraction(&mut text, v);
            }
            text.extend_from_slice(b",\n");
        }
        Ok(text)
    }

    /// The CSV as a string.
    pub fn to_csv(&self) -> Result<String> {
        String::from_utf8(self.csv_bytes()?).map_err(|e| Error::argument("schedule", e.to_string()))
    }

    /// Reads a CSV in the layout [`Self::csv_bytes`] writes (EnergyPlus's eplusshading.csv):
    /// the timestep count comes from the row count, every row's stamp must be the one expected
    /// at its place, and the result passes [`Self::validate`]. `file` names the source in errors.
    pub fn from_csv(file: &str, text: &str) -> Result<Self> {
        let fail = |line: usize, reason: String| Error::model(file, format!("line {line}: {reason}"));
        let mut lines = text.lines();
        let header = lines.next().unwrap_or("");
        let Some(names) = header.strip_prefix("Surface Name,") else {
            return Err(fail(1, format!("expected the header 'Surface Name,NAME,…,', got '{}'", excerpt(header))));
        };
        let names: Vec<String> = csv_fields(names).map(str::to_string).collect();
        let rows: Vec<&str> = lines.collect();
        // 8760·N rows, or 8784·N for a leap year.
        let leap = !rows.len().is_multiple_of(DAYS_HOURS as usize);
        let per_hour = rows.len() / (DAYS_HOURS as usize + 24 * usize::from(leap));
        let timesteps = match Timesteps::new(per_hour as u32).map(|t| t.leap_year(leap)) {
            Ok(t) if rows.len() == t.rows() => t,
            _ => {
                let reason = format!(
                    "{} rows; a year is 8760 (8784 in a leap year) × timesteps per hour (1 2 3 4 5 6 10 12 15 20 30 60) rows",
                    rows.len()
                );
                return Err(Error::model(file, reason));
            }
        };
        let mut values = Vec::with_capacity(rows.len() * names.len());
        for (row, text) in rows.iter().enumerate() {
            let line = row + 2;
            let mut fields = csv_fields(text);
            let stamp = fields.next().unwrap_or("");
            let expected = timesteps.stamp(row);
            if stamp.trim() != expected.trim() {
                return Err(fail(line, format!("timestamp '{}', expected '{}'", excerpt(stamp), expected.trim())));
            }
            let before = values.len();
            // Names first: zip stops on them without taking a surplus value from `fields`.
            for (name, value) in names.iter().zip(fields.by_ref()) {
                let v =
                    value.trim().parse::<f32>().map_err(|_| fail(line, format!("'{}' for '{name}' is not a number", excerpt(value))))?;
                values.push(v);
            }
            let found = values.len() - before + fields.count();
            if found != names.len() {
                return Err(fail(line, format!("{found} values for {} surfaces", names.len())));
            }
        }
        let schedule = Schedule { names, timesteps, values, periods: None };
        schedule.validate().map_err(|e| Error::model(file, e.to_string()))?;
        Ok(schedule)
    }
}

/// Hours in EnergyPlus's schedule year.
const DAYS_HOURS: u32 = crate::year::samples::DAYS * 24;

/// A CSV line's fields, without the one trailing comma EnergyPlus writes (and `\r`).
fn csv_fields(line: &str) -> std::str::Split<'_, char> {
    let line = line.strip_suffix('\r').unwrap_or(line);
    line.strip_suffix(',').unwrap_or(line).split(',')
}

/// At most 40 characters of `text`, for messages.
fn excerpt(text: &str) -> String {
    match text.char_indices().nth(40) {
        Some((at, _)) => format!("{}…", &text[..at]),
        None => text.to_string(),
    }
}

/// Temporary files of writes in progress, so an interrupted process can remove them
/// ([`remove_partial_files`]). The lock is held across each rename, so a remover sees a write
/// either before its rename (and removes the temporary file) or after it (and finds nothing).
static PARTIALS: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn partials() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    // A panic while holding the lock leaves the list as valid as before: keep using it.
    PARTIALS.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Writes `bytes` to `path` atomically: a temporary file beside it, flushed, then renamed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes).map_err(|source| Error::Io { path: path.to_path_buf(), source }))
}

/// Writes `path` atomically from what `write` streams into it (buffered): a temporary file
/// beside it, flushed, then renamed; on any error the temporary file is removed and `path` is
/// left as it was. For outputs too large to build in memory first.
pub fn write_atomic_with(path: &Path, write: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
    let io = |source: std::io::Error, p: &Path| Error::Io { path: p.to_path_buf(), source };
    if is_special(path) {
        return write_through(path, write);
    }
    let tmp = temporary_sibling(path);
    partials().push(tmp.clone());
    let written = (|| {
        let file = std::fs::File::create(&tmp).map_err(|e| io(e, path))?;
        let mut buffered = std::io::BufWriter::with_capacity(1 << 16, file);
        write(&mut buffered)?;
        let file = buffered.into_inner().map_err(|e| io(e.into_error(), path))?;
        file.sync_all().map_err(|e| io(e, path))
    })();
    let mut list = partials();
    let result = written.and_then(|()| std::fs::rename(&tmp, path).map_err(|e| io(e, path)));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    list.retain(|p| *p != tmp);
    result
}

/// Whether `path` exists and is not a regular file (`/dev/null`, `/dev/stdout`, a named pipe):
/// a rename onto it would replace the device with a file (seen: `-o /dev/null` left a regular
/// file there, and every later `> /dev/null` of the machine wrote into it).
fn is_special(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// Writes straight into a device or pipe: there is no file to leave half-written.
fn write_through(path: &Path, write: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
    let file = std::fs::OpenOptions::new().write(true).open(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let mut buffered = std::io::BufWriter::with_capacity(1 << 16, file);
    write(&mut buffered)?;
    buffered.flush().map_err(|source| Error::Io { path: path.to_path_buf(), source })
}

/// Removes the temporary files of writes in progress (from a Ctrl-C handler: the process is
/// about to exit, and a half-written temporary file must not stay beside the output).
pub fn remove_partial_files() {
    remove_listed(&mut partials());
}

fn remove_listed(list: &mut Vec<PathBuf>) {
    for tmp in list.drain(..) {
        let _ = std::fs::remove_file(tmp);
    }
}

fn temporary_sibling(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.partial", std::process::id()))
}

/// Writes a value as the CSV holds it: the f64 of the f32 to 8 decimals. Night and open sky make
/// most values exactly 0 or 1, written without the float formatter (a fifth of a small model's
/// whole run went to formatting).
fn push_fraction(text: &mut Vec<u8>, v: f32) {
    if v == 0.0 && v.is_sign_positive() {
        text.extend_from_slice(b"0.00000000");
    } else if v == 1.0 {
        text.extend_from_slice(b"1.00000000");
    } else {
        let _ = write!(text, "{:.8}", v as f64);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fractions_are_written_as_the_float_formatter_writes_them() {
        let mut values = vec![0.0f32, -0.0, 1.0, 0.5, 1e-9, 0.999_999_9, 0.123_456_78, f32::MIN_POSITIVE];
        values.extend((0..1000).map(|i| (i as f32 * 0.618_034).fract()));
        for v in values {
            let mut ours = Vec::new();
            push_fraction(&mut ours, v);
            assert_eq!(String::from_utf8(ours).unwrap(), format!("{:.8}", v as f64), "{v:e}");
        }
    }

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
        // Left for a look only when an assertion fails.
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn csv_reads_back_what_is_written() {
        let s = schedule();
        let back = Schedule::from_csv("s.csv", &s.to_csv().unwrap()).unwrap();
        assert_eq!(back, s);
        // EnergyPlus's own files may end lines with \r\n.
        let crlf = s.to_csv().unwrap().replace('\n', "\r\n");
        assert_eq!(Schedule::from_csv("s.csv", &crlf).unwrap(), s);
    }

    #[test]
    fn bad_csv_names_line_and_reason() {
        let text = schedule().to_csv().unwrap();
        let cases = [
            (String::new(), "s.csv: line 1: expected the header 'Surface Name,NAME,…,', got ''"),
            (text.replacen(" 01/01 00:30", " 01/01 00:31", 1), "s.csv: line 3: timestamp ' 01/01 00:31', expected '01/01 00:30'"),
            (text.replacen("0.12500000", "half", 1), "s.csv: line 52: 'half' for 'WIN_S' is not a number"),
            (text.replacen("0.12500000", "1.5", 1), "s.csv: invalid schedule: value 1.5 for 'WIN_S' at row 50 is outside [0, 1]"),
            (text.replacen("0.12500000,", "", 1), "s.csv: line 52: 1 values for 2 surfaces"),
            (text.replacen("0.12500000,", "0.1,0.2,", 1), "s.csv: line 52: 3 values for 2 surfaces"),
            (
                text.lines().take(1001).collect::<Vec<_>>().join("\n"),
                "s.csv: 1000 rows; a year is 8760 (8784 in a leap year) × timesteps per hour (1 2 3 4 5 6 10 12 15 20 30 60) rows",
            ),
            (
                text.replacen("WIN_S", "wall_s", 1),
                "s.csv: invalid schedule: surface name 'wall_s' appears twice (EnergyPlus names are case-insensitive)",
            ),
        ];
        for (text, expected) in cases {
            // Not unwrap_err: a wrongly accepted schedule would print 35 040 rows.
            assert_eq!(Schedule::from_csv("s.csv", &text).err().map(|e| e.to_string()).as_deref(), Some(expected));
        }
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
        assert!(partials().iter().all(|p| !p.starts_with(&dir)), "finished writes are unregistered");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A named pipe given as the output stays a pipe and gets the bytes, as `/dev/null` must
    /// stay a device (a rename onto it replaced it with a file). Failed with the rename kept.
    #[cfg(unix)]
    #[test]
    fn writing_to_a_pipe_or_device_writes_through_it() {
        use std::os::unix::fs::FileTypeExt;
        let dir = std::env::temp_dir().join(format!("sunlit-fifo-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("out.csv");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(fifo).unwrap())
        };
        write_atomic(&fifo, b"through").unwrap();
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo(), "the pipe was replaced");
        assert_eq!(reader.join().unwrap(), b"through");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn interrupted_writes_leave_no_temporary_file() {
        let dir = std::env::temp_dir().join(format!("sunlit-interrupted-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("b.csv");
        // A write caught between its temporary file and its rename, as a Ctrl-C would find it
        // (a list of its own: the global one may hold other tests' writes in progress).
        let tmp = temporary_sibling(&path);
        std::fs::write(&tmp, b"half").unwrap();
        let mut list = vec![tmp.clone()];
        remove_listed(&mut list);
        assert!(!tmp.exists() && !path.exists() && list.is_empty());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
