//! The one error type of the library: every failure names the file, object and reason.

use std::path::PathBuf;

/// Everything that can go wrong in sunlit, each variant carrying enough context to act on.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// A model file is malformed as a whole (bad magic, truncated, missing buffers, …).
    #[error("{file}: {reason}")]
    Model {
        /// The file (or a label for in-memory bytes).
        file: String,
        /// What is wrong.
        reason: String,
    },
    /// One object in a model file is unusable (NaN coordinates, zero area, …).
    #[error("{file}: {object}: {reason}")]
    Object {
        /// The file.
        file: String,
        /// The object, e.g. `node 'Wall_S'` or `mesh 3`.
        object: String,
        /// What is wrong.
        reason: String,
    },
    /// Two receivers share a name: output columns would be ambiguous.
    #[error("duplicate receiver name '{name}': {first} and {second}")]
    DuplicateReceiver {
        /// The shared name.
        name: String,
        /// Where the first one came from.
        first: String,
        /// Where the second one came from.
        second: String,
    },
    /// The receiver selection matched nothing.
    #[error("no receiving surface: {0}")]
    NoReceivers(String),
    /// A command-line or API argument is out of range or malformed.
    #[error("invalid {what}: {reason}")]
    Argument {
        /// The argument, e.g. `--sun`.
        what: String,
        /// Why it is refused.
        reason: String,
    },
    /// The GPU could not be set up or failed during a pass.
    #[error("GPU: {0}")]
    Gpu(String),
    /// The GPU device was lost (driver reset, GPU hung or removed, or destroyed): its results are
    /// gone, but a new device may work ([`crate::annual::annual_recovering`] makes one).
    #[error("GPU device lost ({0})")]
    DeviceLost(String),
    /// The caller asked the run to stop (a progress callback said so, or an `AbortSignal` fired).
    #[error("cancelled")]
    Cancelled,
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
}
