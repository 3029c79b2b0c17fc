//! The one error type of the library: every failure names the file, object or parameter, and the
//! reason.
//!
//! Parameters are named as the library names them (`receivers`, `north`, `timesteps_per_hour`,
//! …), never as an edge spells them: [`Error::render`] lets the CLI print its flags
//! (`--receivers`) and the JS API its option names (`timestepsPerHour`) in the same sentences;
//! `Display` uses the library's names.

use std::fmt;
use std::path::PathBuf;

/// Everything that can go wrong in sunlit, each variant carrying enough context to act on.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or written.
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// A model file is malformed as a whole (bad magic, truncated, missing buffers, …).
    Model {
        /// The file (or a label for in-memory bytes).
        file: String,
        /// What is wrong.
        reason: String,
    },
    /// One object in a model file is unusable (NaN coordinates, zero area, …).
    Object {
        /// The file.
        file: String,
        /// The object, e.g. `node 'Wall_S'` or `mesh 3`.
        object: String,
        /// What is wrong.
        reason: String,
    },
    /// An EnergyPlus model's Timestep differs from the schedule's timesteps per hour (the
    /// `timesteps_per_hour` parameter): EnergyPlus would refuse the CSV.
    TimestepMismatch {
        /// The model file.
        file: String,
        /// Its Timestep object.
        object: String,
        /// Timesteps per hour the model runs.
        model: u32,
        /// Timesteps per hour the schedule has.
        schedule: u32,
    },
    /// Two receivers share a name: output columns would be ambiguous.
    DuplicateReceiver {
        /// The shared name.
        name: String,
        /// Where the first one came from.
        first: String,
        /// Where the second one came from.
        second: String,
    },
    /// The receiver selection matched nothing.
    NoReceivers(NoReceivers),
    /// A parameter is out of range or malformed.
    Argument {
        /// The parameter, e.g. `sun` or `timesteps_per_hour`.
        what: String,
        /// Why it is refused.
        reason: String,
    },
    /// A node pattern given for a parameter (`foliage`, `transmittance`) matched no node.
    Unmatched {
        /// The parameter.
        what: String,
        /// The pattern as given (`pine*`, or `screen*=0.4`).
        pattern: String,
    },
    /// The GPU could not be set up or failed during a pass.
    Gpu(GpuError),
    /// The GPU device was lost (driver reset, GPU hung or removed, or destroyed): its results are
    /// gone, but a new device may work ([`crate::year::annual::annual_recovering`] makes one).
    DeviceLost(String),
    /// The caller asked the run to stop (a progress callback said so, or an `AbortSignal` fired).
    Cancelled,
    /// Bytes given as an encoded scene ([`crate::scene::Scene::from_bytes`]) are not one.
    SceneBytes(SceneBytesError),
}

/// Why bytes do not decode as a scene ([`crate::scene::codec`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum SceneBytesError {
    /// They do not start with the encoding's magic.
    NotAScene,
    /// They were written by another version of the encoding.
    Version {
        /// The version they carry.
        found: u32,
        /// The one this build reads.
        supported: u32,
    },
    /// They end before what is being read (or a list's length exceeds the bytes left).
    Truncated {
        /// What was being read, e.g. `mesh indices`.
        reading: &'static str,
        /// Where, in bytes from the start.
        offset: usize,
        /// Bytes it needs.
        need: usize,
        /// Bytes left.
        left: usize,
    },
    /// A part refers past its lists or holds a non-finite number.
    Invalid {
        /// The part, e.g. `instance 3` or `mesh 0 ('static')`.
        what: String,
        /// What is wrong.
        reason: String,
    },
    /// Bytes follow the encoded scene.
    TrailingBytes {
        /// How many.
        extra: usize,
    },
}

impl fmt::Display for SceneBytesError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SceneBytesError::NotAScene => f.write_str("they are not an encoded scene (no SUNLITSC magic)"),
            SceneBytesError::Version { found, supported } => {
                write!(f, "they are version {found} of the encoding; this build reads version {supported}")
            }
            SceneBytesError::Truncated { reading, offset, need, left } => {
                write!(f, "truncated: reading {reading} at byte {offset} needs {need} bytes, {left} are left")
            }
            SceneBytesError::Invalid { what, reason } => write!(f, "{what}: {reason}"),
            SceneBytesError::TrailingBytes { extra } => write!(f, "{extra} bytes follow the scene"),
        }
    }
}

/// Why no receiving surface was chosen.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum NoReceivers {
    /// No node name matches the `receivers` patterns.
    Unmatched(Vec<String>),
    /// No pattern was given and no node is named (the default picks named nodes).
    Unnamed,
    /// Any other reason, in words that name no parameter.
    Other(String),
    /// The `where` rules (receivers by attribute) left no surface of those otherwise chosen.
    Where {
        /// The rule (or rules, comma-separated) that left none, as given.
        rule: String,
        /// Why, naming the attribute.
        reason: String,
    },
}

/// What went wrong on the GPU (a lost device is [`Error::DeviceLost`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum GpuError {
    /// No adapter: no WebGPU in the browser, no Vulkan driver natively.
    NoAdapter {
        /// What to install or enable.
        hint: String,
        /// What wgpu said.
        reason: String,
    },
    /// The adapter would not open a device.
    Device(String),
    /// The device ran out of memory while `doing`; a smaller `resolution` needs less.
    OutOfMemory {
        /// The stage, e.g. `counting pixels`.
        doing: String,
        /// The tile side in use.
        resolution: u32,
    },
    /// The scene needs a buffer larger than one of the device's limits.
    OverLimit {
        /// The limit, e.g. `max_buffer_size`.
        limit_name: &'static str,
        /// Bytes needed.
        need: u64,
        /// Bytes allowed.
        limit: u64,
    },
    /// wgpu's validation refused a command (a bug in sunlit, or a driver's).
    Validation {
        /// The stage.
        doing: String,
        /// What wgpu said.
        message: String,
    },
    /// Reading results back from the GPU failed.
    Readback(String),
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// An [`Error::Argument`].
    pub fn argument(what: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Argument { what: what.into(), reason: reason.into() }
    }

    /// An [`Error::Model`].
    pub fn model(file: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Model { file: file.into(), reason: reason.into() }
    }

    /// An [`Error::Object`].
    pub fn object(file: impl Into<String>, object: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Object { file: file.into(), object: object.into(), reason: reason.into() }
    }

    /// The parameter this error is about, if it is about one (as the library names it).
    pub fn parameter(&self) -> Option<&str> {
        match self {
            Error::Argument { what, .. } | Error::Unmatched { what, .. } => Some(what),
            Error::NoReceivers(NoReceivers::Unmatched(_)) => Some("receivers"),
            Error::NoReceivers(NoReceivers::Where { .. }) => Some("where"),
            Error::TimestepMismatch { .. } => Some("timesteps_per_hour"),
            _ => None,
        }
    }

    /// A stable, kebab-case name of the kind of failure, for programs to switch on (the JS API's
    /// `code`): `io`, `model`, `object`, `timestep-mismatch`, `duplicate-receiver`,
    /// `no-receivers`, `bad-option`, `gpu`, `device-lost`, `cancelled`, `scene-bytes`.
    pub fn code(&self) -> &'static str {
        match self {
            Error::Io { .. } => "io",
            Error::Model { .. } => "model",
            Error::Object { .. } => "object",
            Error::TimestepMismatch { .. } => "timestep-mismatch",
            Error::DuplicateReceiver { .. } => "duplicate-receiver",
            Error::NoReceivers(_) => "no-receivers",
            Error::Argument { .. } | Error::Unmatched { .. } => "bad-option",
            Error::Gpu(_) => "gpu",
            Error::DeviceLost(_) => "device-lost",
            Error::Cancelled => "cancelled",
            Error::SceneBytes(_) => "scene-bytes",
        }
    }

    /// The file this error is about, if it is about one.
    pub fn file(&self) -> Option<String> {
        match self {
            Error::Io { path, .. } => Some(path.display().to_string()),
            Error::Model { file, .. } | Error::Object { file, .. } | Error::TimestepMismatch { file, .. } => Some(file.clone()),
            _ => None,
        }
    }

    /// The object in a file this error is about, if it is about one.
    pub fn object_name(&self) -> Option<&str> {
        match self {
            Error::Object { object, .. } | Error::TimestepMismatch { object, .. } => Some(object),
            _ => None,
        }
    }

    /// The message, with every parameter named by `name` (given the library's name, e.g.
    /// `timesteps_per_hour`; a name made of parts, `leaf_out/leaf_fall`, is passed part by part).
    pub fn render(&self, name: &dyn Fn(&str) -> String) -> String {
        let name = |param: &str| param.split('/').map(name).collect::<Vec<_>>().join("/");
        match self {
            Error::Io { path, source } => format!("{}: {source}", path.display()),
            Error::Model { file, reason } => format!("{file}: {reason}"),
            Error::Object { file, object, reason } => format!("{file}: {object}: {reason}"),
            Error::TimestepMismatch { file, object, model, schedule } => format!(
                "{file}: {object}: the model runs {model} timesteps per hour but the CSV has {schedule}: use {} {model}",
                name("timesteps_per_hour")
            ),
            Error::DuplicateReceiver { name, first, second } => format!("duplicate receiver name '{name}': {first} and {second}"),
            Error::NoReceivers(why) => format!("no receiving surface: {}", why.render(&name)),
            Error::Argument { what, reason } => format!("invalid {}: {reason}", name(what)),
            Error::Unmatched { what, pattern } => format!("invalid {} {pattern}: no glTF node name matches it", name(what)),
            Error::Gpu(e) => format!("GPU: {}", e.render(&name)),
            Error::DeviceLost(why) => format!("GPU device lost ({why})"),
            Error::Cancelled => "cancelled".into(),
            Error::SceneBytes(why) => format!("encoded scene: {why}"),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.render(&str::to_string))
    }
}

impl NoReceivers {
    fn render(&self, name: &dyn Fn(&str) -> String) -> String {
        match self {
            NoReceivers::Unmatched(patterns) => format!("no node name matches {} {}", name("receivers"), patterns.join(", ")),
            NoReceivers::Unnamed => {
                format!("the models have no named node with a mesh (name nodes, mark them in extras, or use {})", name("receivers"))
            }
            NoReceivers::Other(reason) => reason.clone(),
            NoReceivers::Where { rule, reason } => format!("{} {rule}: {reason}", name("where")),
        }
    }
}

impl GpuError {
    /// A stable, kebab-case name of the kind of GPU failure: `no-adapter`, `device`,
    /// `out-of-memory`, `over-limit`, `validation`, `readback`.
    pub fn code(&self) -> &'static str {
        match self {
            GpuError::NoAdapter { .. } => "no-adapter",
            GpuError::Device(_) => "device",
            GpuError::OutOfMemory { .. } => "out-of-memory",
            GpuError::OverLimit { .. } => "over-limit",
            GpuError::Validation { .. } => "validation",
            GpuError::Readback(_) => "readback",
        }
    }

    fn render(&self, name: &dyn Fn(&str) -> String) -> String {
        let mib = |b: u64| b as f64 / (1 << 20) as f64;
        match self {
            GpuError::NoAdapter { hint, reason } => format!("{hint} ({reason})"),
            GpuError::Device(reason) => format!("could not open the GPU device: {reason}"),
            GpuError::OutOfMemory { doing, resolution } => format!(
                "{doing}: out of GPU memory; lower {} (now {resolution}) or count fewer triangles (split the model)",
                name("resolution")
            ),
            GpuError::OverLimit { limit_name, need, limit } => format!(
                "the scene needs a {:.0} MiB buffer, more than this GPU's {:.0} MiB limit ({limit_name}): count fewer triangles or placements (split the model, or leave out far context)",
                mib(*need),
                mib(*limit)
            ),
            GpuError::Validation { doing, message } => format!("{doing}: {message}"),
            GpuError::Readback(reason) => reason.clone(),
        }
    }
}

impl From<GpuError> for Error {
    fn from(e: GpuError) -> Self {
        Error::Gpu(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_edge_names_the_parameters_in_its_own_words() {
        let flag = |p: &str| format!("--{}", p.replace('_', "-"));
        let e = Error::argument("timesteps_per_hour", "7 is not one EnergyPlus accepts");
        assert_eq!(e.to_string(), "invalid timesteps_per_hour: 7 is not one EnergyPlus accepts");
        assert_eq!(e.render(&flag), "invalid --timesteps-per-hour: 7 is not one EnergyPlus accepts");
        let e = Error::argument("leaf_out/leaf_fall", "out of order");
        assert_eq!(e.render(&flag), "invalid --leaf-out/--leaf-fall: out of order");
        let e = Error::NoReceivers(NoReceivers::Unmatched(vec!["Roof*".into()]));
        assert_eq!(e.render(&flag), "no receiving surface: no node name matches --receivers Roof*");
        assert_eq!(e.parameter(), Some("receivers"));
        let e = Error::Gpu(GpuError::OutOfMemory { doing: "counting pixels".into(), resolution: 512 });
        assert!(e.render(&flag).contains("lower --resolution (now 512)"), "{e}");
        assert!(e.to_string().contains("lower resolution (now 512)"), "{e}");
        assert_eq!(e.code(), "gpu");
        assert_eq!(Error::argument("north", "NaN").code(), "bad-option");
        assert_eq!(Error::object("a.idf", "Timestep", "bad").object_name(), Some("Timestep"));
    }
}
