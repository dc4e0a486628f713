//! Error types and the exit code of each kind, decided in one place.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where in an input file a problem is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// The whole file.
    File,
    /// A 1-based line of a text file.
    Line(u64),
    /// A byte offset (binary files).
    Byte(u64),
}

/// A problem with the input model: names the file, the element, what is wrong and what
/// the user can do about it. Always shown on one line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InputError {
    /// The model file.
    pub path: PathBuf,
    /// Where in the file.
    pub location: Location,
    /// What is wrong, naming the element (face, edge, vertex) in the file's numbering.
    pub problem: String,
    /// What the user can do.
    pub fix: String,
}

impl InputError {
    /// A new input error.
    pub fn new(
        path: &Path,
        location: Location,
        problem: impl Into<String>,
        fix: impl Into<String>,
    ) -> Self {
        Self {
            path: path.to_path_buf(),
            location,
            problem: problem.into(),
            fix: fix.into(),
        }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        match self.location {
            Location::File => {}
            Location::Line(n) => write!(f, ":{n}")?,
            Location::Byte(n) => write!(f, ": byte {n}")?,
        }
        write!(f, ": {}", self.problem)?;
        if !self.fix.is_empty() {
            write!(f, " ({})", self.fix)?;
        }
        Ok(())
    }
}

impl std::error::Error for InputError {}

/// Every failure the library reports. The variant decides the exit code.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Options or configuration the tool cannot use (exit code 2).
    #[error("{0}")]
    Usage(String),
    /// An input model that cannot be used (exit code 3).
    #[error(transparent)]
    Input(#[from] InputError),
    /// Anything that fails while running: output folder not writable, a panel larger
    /// than the sheet, an internal error (exit code 1).
    #[error("{0}")]
    Runtime(String),
}

impl Error {
    /// The process exit code for this error: 1 runtime, 2 usage, 3 bad input model.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Runtime(_) => 1,
            Error::Usage(_) => 2,
            Error::Input(_) => 3,
        }
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
