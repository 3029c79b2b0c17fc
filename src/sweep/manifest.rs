//! The sweep manifest: JSON Lines, one variant a line, read and checked before anything runs.
//!
//! A line is an object with an `"id"` (a safe file name, unique) and the long options of one
//! annual run as keys, values as they would be written after the option: `"models": [...]` for
//! the model files, an array for a repeatable option, `true` for a flag, a string or number for
//! the rest. The option set is not listed here: the caller passes a [`Schema`] (the command line
//! derives it from its own annual arguments), so an option added there is a manifest key at once.
//! Each line becomes the argument list of that annual run ([`Variant::args`]); paths are
//! resolved against the manifest's folder and must name existing files. Every problem is
//! collected with its line number, so one pass reports them all.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::error::{Error, Result};

/// The key naming the model files (the annual run's positional arguments).
pub const MODELS: &str = "models";
/// The key asking for the hooked EnergyPlus copy; in a sweep only `true` or `false`, since the
/// copy is written beside the variant's CSV as `<id>.idf` or `<id>.epJSON`.
pub const IDF_OUT: &str = "idf-out";
/// The key of the output CSV, which the sweep sets (`<id>.csv`) and a line may not.
pub const OUTPUT: &str = "output";
/// The key of the annual run's per-surface summary, which the sweep sets for a variant with an
/// `epw` (`<id>.summary.json`, read back for summary.csv's irradiation) and a line may not.
pub const SUMMARY: &str = "summary";
/// The key of the weather file: with it, a variant has annual irradiation.
const EPW: &str = "epw";
/// Ids a variant may not take: its CSV would overwrite the sweep's own outputs.
const RESERVED_IDS: [&str; 2] = ["summary", "failed"];
/// Longest id (file systems allow 255 bytes a name; the id gets suffixes).
const MAX_ID: usize = 100;

/// How an option takes its value on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OptionKind {
    /// A switch: `true` sets it, `false` leaves it out.
    Flag,
    /// One value.
    Value,
    /// Repeatable: an array gives one occurrence per element (a single value gives one).
    Repeated,
}

/// One option a manifest line may set.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OptionSpec {
    /// The long name, without dashes, as it appears as a key.
    pub key: String,
    /// How it takes its value.
    pub kind: OptionKind,
    /// Its values are file paths (resolved against the manifest's folder, must exist).
    pub path: bool,
}

/// The options of the annual run (besides `models`, which is always there).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Schema {
    /// The options, in the order they are listed in messages.
    pub options: Vec<OptionSpec>,
}

impl Schema {
    fn get(&self, key: &str) -> Option<&OptionSpec> {
        self.options.iter().find(|o| o.key == key)
    }

    /// Every key a line may use, for the unknown-key message.
    fn keys(&self) -> String {
        let mut keys = vec!["id", MODELS];
        keys.extend(self.options.iter().map(|o| o.key.as_str()).filter(|k| *k != OUTPUT && *k != SUMMARY));
        keys.join(", ")
    }
}

/// One variant: a manifest line turned into the arguments of its annual run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Variant {
    /// Line number in the manifest (1-based).
    pub line: usize,
    /// Position among the manifest's variants (0-based): the index a job array task takes.
    pub index: usize,
    /// The id, a safe file name.
    pub id: String,
    /// The line's settings as given (key, value as text; arrays joined by `;`), sorted by key.
    pub settings: Vec<(String, String)>,
    /// The annual run's options as `--key=value` (sorted by key, paths absolute), then `--` and
    /// the model paths; without the output, which depends on the folder.
    pub args: Vec<String>,
    /// The extension of the hooked EnergyPlus copy when the line asks for one (`idf`, `epJSON`).
    pub idf_out: Option<String>,
    /// Every input file the run reads (models and path options), absolute.
    pub inputs: Vec<PathBuf>,
}

impl Variant {
    /// The variant's CSV in `dir`.
    pub fn csv(&self, dir: &Path) -> PathBuf {
        dir.join(format!("{}.csv", self.id))
    }

    /// The hooked EnergyPlus copy in `dir`, when asked for.
    pub fn model_copy(&self, dir: &Path) -> Option<PathBuf> {
        self.idf_out.as_ref().map(|ext| dir.join(format!("{}.{ext}", self.id)))
    }

    /// The per-surface summary in `dir` (mean fraction, irradiation, unshaded irradiation),
    /// written for a variant with an `epw`, whose weather gives the irradiation.
    pub fn surface_summary(&self, dir: &Path) -> Option<PathBuf> {
        self.arg(EPW).map(|_| dir.join(format!("{}.summary.json", self.id)))
    }

    /// Every file the run writes in `dir`.
    pub fn outputs(&self, dir: &Path) -> Vec<PathBuf> {
        std::iter::once(self.csv(dir)).chain(self.model_copy(dir)).chain(self.surface_summary(dir)).collect()
    }

    /// The whole argument list of the annual run writing into `dir` (after the program name and
    /// the subcommand): options, outputs, `--`, models.
    pub fn args_into(&self, dir: &Path) -> Vec<String> {
        let split = self.args.iter().position(|a| a == "--").unwrap_or(self.args.len());
        let mut args = self.args[..split].to_vec();
        args.push(format!("--{OUTPUT}={}", self.csv(dir).display()));
        if let Some(copy) = self.model_copy(dir) {
            args.push(format!("--{IDF_OUT}={}", copy.display()));
        }
        if let Some(summary) = self.surface_summary(dir) {
            args.push(format!("--{SUMMARY}={}", summary.display()));
        }
        args.extend_from_slice(&self.args[split..]);
        args
    }

    /// The value of option `key` in [`Self::args`] (its first occurrence), paths resolved.
    pub fn arg(&self, key: &str) -> Option<&str> {
        let prefix = format!("--{key}=");
        self.args.iter().take_while(|a| *a != "--").find_map(|a| a.strip_prefix(&prefix))
    }

    /// A setting's value as given, if the line has it.
    pub fn setting(&self, key: &str) -> Option<&str> {
        self.settings.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }
}

/// A bad line: its number and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// Line number (1-based).
    pub line: usize,
    /// What is wrong.
    pub reason: String,
}

/// A read manifest: its variants and every problem found.
#[derive(Debug, Clone, Default)]
pub struct Manifest {
    /// The manifest file (absolute), for messages and for re-running it.
    pub path: PathBuf,
    /// The good lines' variants, in file order.
    pub variants: Vec<Variant>,
    /// Every bad line's problems, in line order.
    pub problems: Vec<Problem>,
}

impl Manifest {
    /// Reads the manifest at `path`; relative paths in it resolve against its folder.
    pub fn read(path: &Path, schema: &Schema) -> Result<Self> {
        let path = std::path::absolute(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
        let text = std::fs::read_to_string(&path).map_err(|source| Error::Io { path: path.clone(), source })?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok(Self { path, ..Self::parse(&text, &base, schema) })
    }

    /// Parses manifest text; relative paths resolve against `base`. Blank lines are skipped.
    pub fn parse(text: &str, base: &Path, schema: &Schema) -> Self {
        let mut manifest = Self::default();
        let mut seen: HashMap<String, usize> = HashMap::new();
        for (n, raw) in text.lines().enumerate() {
            let line = n + 1;
            if raw.trim().is_empty() {
                continue;
            }
            let mut problems = Vec::new();
            let variant = parse_line(raw, line, manifest.variants.len(), base, schema, &mut problems);
            if let Some(v) = &variant {
                // Case-insensitive: on some file systems A.csv and a.csv are one file.
                match seen.get(&v.id.to_lowercase()) {
                    Some(first) => problems.push(format!("id '{}' is already used on line {first}", v.id)),
                    None => {
                        seen.insert(v.id.to_lowercase(), line);
                    }
                }
            }
            match variant {
                Some(v) if problems.is_empty() => manifest.variants.push(v),
                _ => manifest.problems.extend(problems.into_iter().map(|reason| Problem { line, reason })),
            }
        }
        if manifest.variants.is_empty() && manifest.problems.is_empty() {
            manifest.problems.push(Problem { line: 0, reason: "no variants (one JSON object a line)".into() });
        }
        manifest
    }

    /// Adds problems found by the caller (e.g. values its own parser refused), then orders all
    /// by line.
    pub fn add_problems(&mut self, more: impl IntoIterator<Item = Problem>) {
        self.problems.extend(more);
        self.problems.sort_by_key(|p| p.line);
        let bad: std::collections::HashSet<usize> = self.problems.iter().map(|p| p.line).collect();
        self.variants.retain(|v| !bad.contains(&v.line));
    }

    /// Fails with every problem, one a line, when there are any.
    pub fn check(&self) -> Result<()> {
        if self.problems.is_empty() {
            return Ok(());
        }
        let lines: Vec<String> =
            self.problems.iter().map(|p| if p.line == 0 { p.reason.clone() } else { format!("line {}: {}", p.line, p.reason) }).collect();
        let count = self.problems.iter().map(|p| p.line).collect::<std::collections::BTreeSet<_>>().len();
        let what = if count == 1 { "1 bad line".to_string() } else { format!("{count} bad lines") };
        Err(Error::model(self.path.display().to_string(), format!("{what}, nothing run:\n  {}", lines.join("\n  "))))
    }
}

/// One line, or `None` when it is not an object with a usable id; problems go to `problems`.
fn parse_line(raw: &str, line: usize, index: usize, base: &Path, schema: &Schema, problems: &mut Vec<String>) -> Option<Variant> {
    let object = match serde_json::from_str::<Value>(raw) {
        Ok(Value::Object(map)) => map,
        Ok(other) => {
            problems.push(format!("expected a JSON object, got {}", kind_of(&other)));
            return None;
        }
        Err(e) => {
            problems.push(format!("not JSON: {e}"));
            return None;
        }
    };
    let id = match object.get("id") {
        Some(Value::String(id)) => match id_problem(id) {
            Some(reason) => {
                problems.push(reason);
                None
            }
            None => Some(id.clone()),
        },
        Some(other) => {
            problems.push(format!("id must be a string, got {}", kind_of(other)));
            None
        }
        None => {
            problems.push("no \"id\"".into());
            None
        }
    };
    let mut options: Vec<String> = Vec::new();
    let mut models: Vec<String> = Vec::new();
    let mut settings = Vec::new();
    let mut inputs = Vec::new();
    let mut idf_out = false;
    // serde_json's map is ordered by key, so the arguments are too: equal lines, equal runs.
    for (key, value) in &object {
        if key == "id" {
            continue;
        }
        settings.push((key.clone(), setting_text(value)));
        if key == MODELS {
            match strings(value, true) {
                Ok(list) if list.is_empty() => problems.push(format!("{MODELS} is empty")),
                Ok(list) => models = list,
                Err(reason) => problems.push(format!("{MODELS}: {reason}")),
            }
            continue;
        }
        if key == OUTPUT {
            problems.push(format!("{OUTPUT} is set by the sweep (<id>.csv in the output folder); leave it out"));
            continue;
        }
        if key == SUMMARY {
            problems.push(format!("{SUMMARY} is set by the sweep (<id>.summary.json, with an {EPW}); leave it out"));
            continue;
        }
        if key == IDF_OUT {
            match value {
                Value::Bool(b) => idf_out = *b,
                other => problems.push(format!(
                    "{IDF_OUT} is true or false in a sweep (the copy is written as <id>.idf or <id>.epJSON), got {}",
                    kind_of(other)
                )),
            }
            continue;
        }
        let Some(spec) = schema.get(key) else {
            problems.push(format!("unknown key '{key}' (known: {})", schema.keys()));
            continue;
        };
        match option_args(spec, value) {
            Ok(values) => {
                for v in values {
                    let v = if spec.path { resolve(base, &v, key, problems, &mut inputs) } else { v };
                    options.push(match spec.kind {
                        OptionKind::Flag => format!("--{key}"),
                        _ => format!("--{key}={v}"),
                    });
                }
            }
            Err(reason) => problems.push(format!("{key}: {reason}")),
        }
    }
    if models.is_empty() && !object.contains_key(MODELS) {
        problems.push(format!("no \"{MODELS}\" (the model files)"));
    }
    let models: Vec<String> = models.iter().map(|m| resolve(base, m, MODELS, problems, &mut inputs)).collect();
    let idf_out = if idf_out {
        match models.iter().find_map(|m| energyplus_extension(m)) {
            Some(ext) => Some(ext.to_string()),
            None => {
                problems.push(format!("{IDF_OUT} needs an EnergyPlus model (.idf or .epJSON) among the {MODELS}"));
                None
            }
        }
    } else {
        None
    };
    let mut args = options;
    args.push("--".into());
    args.extend(models);
    Some(Variant { line, index, id: id?, settings, args, idf_out, inputs })
}

/// Why `id` cannot be a file name in the output folder, if it cannot.
fn id_problem(id: &str) -> Option<String> {
    let safe = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.');
    if id.is_empty() || id.len() > MAX_ID {
        return Some(format!("id '{id}' must be 1 to {MAX_ID} characters"));
    }
    if !id.chars().all(safe) || id.starts_with('.') || id.starts_with('-') {
        return Some(format!("id '{id}' is not a safe file name (letters, digits, '_', '-', '.', not starting with '.' or '-')"));
    }
    if RESERVED_IDS.iter().any(|r| r.eq_ignore_ascii_case(id)) {
        return Some(format!("id '{id}' is reserved for the sweep's own {id}.csv"));
    }
    None
}

/// The command-line values of one option, or why the JSON value does not fit it.
fn option_args(spec: &OptionSpec, value: &Value) -> std::result::Result<Vec<String>, String> {
    match (spec.kind, value) {
        (OptionKind::Flag, Value::Bool(true)) => Ok(vec![String::new()]),
        (OptionKind::Flag, Value::Bool(false)) => Ok(vec![]),
        (OptionKind::Flag, other) => Err(format!("a switch: true or false, got {}", kind_of(other))),
        (OptionKind::Value, v) => scalar(v).map(|s| vec![s]),
        (OptionKind::Repeated, v) => strings(v, false),
    }
}

/// A string or number as command-line text.
fn scalar(value: &Value) -> std::result::Result<String, String> {
    match value {
        Value::String(s) => Ok(s.clone()),
        Value::Number(n) => Ok(n.to_string()),
        other => Err(format!("expected a string or number, got {}", kind_of(other))),
    }
}

/// A value or an array of values as command-line texts (`paths_only`: strings only).
fn strings(value: &Value, paths_only: bool) -> std::result::Result<Vec<String>, String> {
    let one = |v: &Value| match v {
        Value::String(s) => Ok(s.clone()),
        Value::Number(_) if !paths_only => scalar(v),
        other => Err(format!("expected {}, got {}", if paths_only { "file names" } else { "strings or numbers" }, kind_of(other))),
    };
    match value {
        Value::Array(items) => items.iter().map(one).collect(),
        single => one(single).map(|s| vec![s]),
    }
}

/// `path` made absolute against `base`; a missing file is a problem (named by `key`).
fn resolve(base: &Path, path: &str, key: &str, problems: &mut Vec<String>, inputs: &mut Vec<PathBuf>) -> String {
    let full = base.join(path);
    if !full.is_file() {
        problems.push(format!("{key}: no file {}", full.display()));
    }
    inputs.push(full.clone());
    full.display().to_string()
}

/// The extension the hooked copy of an EnergyPlus model keeps, if `path` is one.
fn energyplus_extension(path: &str) -> Option<&'static str> {
    let ext = Path::new(path).extension()?.to_string_lossy().to_lowercase();
    match ext.as_str() {
        "idf" => Some("idf"),
        "epjson" => Some("epJSON"),
        _ => None,
    }
}

/// A setting as text for the summary: arrays joined by `;`.
fn setting_text(value: &Value) -> String {
    match value {
        Value::String(s) => s.clone(),
        Value::Array(items) => items.iter().map(setting_text).collect::<Vec<_>>().join(";"),
        other => other.to_string(),
    }
}

fn kind_of(value: &Value) -> &'static str {
    match value {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn schema() -> Schema {
        let spec = |key: &str, kind, path| OptionSpec { key: key.into(), kind, path };
        Schema {
            options: vec![
                spec("epw", OptionKind::Value, true),
                spec("location", OptionKind::Value, false),
                spec("north", OptionKind::Value, false),
                spec("receivers", OptionKind::Repeated, false),
                spec("dense", OptionKind::Flag, false),
                spec("output", OptionKind::Value, true),
                spec("idf-out", OptionKind::Value, true),
            ],
        }
    }

    fn folder() -> PathBuf {
        let dir = std::env::temp_dir().join(format!("sunlit-manifest-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for f in ["a.glb", "b.idf"] {
            std::fs::write(dir.join(f), b"x").unwrap();
        }
        dir
    }

    #[test]
    fn a_line_becomes_sorted_arguments_with_absolute_paths() {
        let dir = folder();
        let text =
            r#"{"id": "v1", "north": -90, "models": ["a.glb"], "receivers": ["WIN_*", "ROOF"], "dense": true, "location": "46.5,11.35,1"}"#;
        let m = Manifest::parse(text, &dir, &schema());
        assert!(m.problems.is_empty(), "{:?}", m.problems);
        let v = &m.variants[0];
        let model = dir.join("a.glb").display().to_string();
        assert_eq!(v.args, ["--dense", "--location=46.5,11.35,1", "--north=-90", "--receivers=WIN_*", "--receivers=ROOF", "--", &model]);
        let out = Path::new("/o");
        assert_eq!(v.args_into(out)[5..], ["--output=/o/v1.csv".to_string(), "--".into(), model]);
        assert_eq!(v.setting("receivers"), Some("WIN_*;ROOF"));
        assert_eq!(v.idf_out, None);
    }

    #[test]
    fn idf_out_follows_the_energyplus_input() {
        let dir = folder();
        let m = Manifest::parse(r#"{"id": "h", "models": ["b.idf", "a.glb"], "idf-out": true}"#, &dir, &schema());
        assert!(m.problems.is_empty(), "{:?}", m.problems);
        assert_eq!(m.variants[0].model_copy(Path::new("/o")), Some(PathBuf::from("/o/h.idf")));
        assert!(m.variants[0].args_into(Path::new("/o")).contains(&"--idf-out=/o/h.idf".to_string()));
    }

    #[test]
    fn every_bad_line_is_reported_with_its_number() {
        let dir = folder();
        let text = [
            r#"{"id": "ok", "models": "a.glb"}"#,
            r#"{"id": "x", "nrth": 3, "models": ["a.glb"]}"#,
            r#"{"id": "ok", "models": ["a.glb"]}"#,
            "",
            r#"{"id": "../up", "models": ["a.glb"]}"#,
            r#"{"id": "m", "models": ["missing.glb"]}"#,
            r#"{"id": "f", "models": ["a.glb"], "dense": "yes"}"#,
            r#"not json"#,
            r#"{"id": "o", "models": ["a.glb"], "output": "x.csv", "idf-out": true}"#,
            r#"{"id": "summary", "models": ["a.glb"]}"#,
        ]
        .join("\n");
        let m = Manifest::parse(&text, &dir, &schema());
        let lines: Vec<usize> = m.problems.iter().map(|p| p.line).collect();
        assert_eq!(lines, [2, 3, 5, 6, 7, 8, 9, 9, 10], "{:?}", m.problems);
        assert_eq!(m.variants.len(), 1);
        let e = m.check().unwrap_err().to_string();
        for needle in [
            "8 bad lines",
            "line 2: unknown key 'nrth'",
            "line 3: id 'ok' is already used on line 1",
            "line 5: id '../up' is not a safe file name",
            "line 6: models: no file",
            "line 7: dense: a switch: true or false, got a string",
            "line 8: not JSON",
            "line 9: output is set by the sweep",
            "line 9: idf-out needs an EnergyPlus model",
            "line 10: id 'summary' is reserved",
        ] {
            assert!(e.contains(needle), "'{needle}' in {e}");
        }
    }

    #[test]
    fn caller_problems_join_in_line_order() {
        let dir = folder();
        let text = "{\"id\": \"a\", \"models\": \"a.glb\"}\n{\"id\": \"b\", \"models\": \"a.glb\"}\n{\"id\": \"c\", \"nope\": 1}";
        let mut m = Manifest::parse(text, &dir, &schema());
        m.add_problems([Problem { line: 1, reason: "north: not a number".into() }]);
        assert_eq!(m.problems.iter().map(|p| p.line).collect::<Vec<_>>(), [1, 3, 3]);
        assert_eq!(m.variants.iter().map(|v| v.id.as_str()).collect::<Vec<_>>(), ["b"]);
        assert!(Manifest::parse("\n\n", &dir, &schema()).check().unwrap_err().to_string().contains("no variants"));
    }
}
