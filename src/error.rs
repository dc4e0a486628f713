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

/// Every failure the library reports. The variant decides the exit code
/// ([`Error::exit_code`]); causes stay attached as sources, and `unfold` prints the
/// whole chain.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Options or configuration the tool cannot use, or that do not fit the model (a
    /// panel larger than the sheet) (exit code 2).
    #[error("{0}")]
    Usage(String),
    /// An input model that cannot be used (exit code 3).
    #[error(transparent)]
    Input(#[from] InputError),
    /// The model cannot be built as asked: a panel that overlaps itself, connections
    /// without a fastener under `--strict` (exit code 1).
    #[error("{0}")]
    Build(String),
    /// A file or folder that cannot be read or written (exit code 1).
    #[error("cannot {action} {}: {source} (choose a writable --out folder)", path.display())]
    Io {
        /// What was being done ("create", "rename").
        action: String,
        /// On what.
        path: PathBuf,
        /// The system's error.
        #[source]
        source: std::io::Error,
    },
    /// A failure that is a bug of unfold, not a mistake of the user (exit code 1).
    #[error("internal error while {doing}; this is a bug in unfold: please report it with the model file and the command line")]
    Internal {
        /// The step that failed ("unrolling the panels").
        doing: String,
        /// What failed inside it.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// A model too detailed for its size, stopped before the long stages (exit code
    /// 2): most of its panels could not carry their ids or fastener holes.
    #[error("{message}")]
    TooDetailed {
        /// The sentence naming what would go wrong and the fixes.
        message: String,
        /// The `--target-edges` budget that was tried and builds clean, if one was found.
        budget: Option<usize>,
    },
    /// A panic: a bug of unfold, caught and reported on one line (exit code 1).
    #[error("internal error while {stage}{}: {message}; this is a bug in unfold: please report it with the model file and the command line", panel.as_ref().map(|id| format!(" (panel {id})")).unwrap_or_default())]
    Panic {
        /// The stage that was running ("nesting 41 panels on sheets").
        stage: String,
        /// The id of the panel it was working on, where one was.
        panel: Option<String>,
        /// What the panic said, and where.
        message: String,
    },
}

impl Error {
    /// An internal error of `doing`, caused by `source`.
    pub fn internal(
        doing: &str,
        source: impl Into<Box<dyn std::error::Error + Send + Sync>>,
    ) -> Error {
        Error::Internal {
            doing: doing.to_string(),
            source: source.into(),
        }
    }

    /// The process exit code for this error: 1 runtime, 2 usage, 3 bad input model.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Build(_) | Error::Io { .. } | Error::Internal { .. } | Error::Panic { .. } => 1,
            Error::Usage(_) | Error::TooDetailed { .. } => 2,
            Error::Input(_) => 3,
        }
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn internal_errors_say_they_are_bugs_and_keep_their_cause() {
        let cause = std::io::Error::other("facet 3 has no area");
        let e = Error::internal("unrolling the panels", cause);
        let text = e.to_string();
        assert!(
            text.contains("internal error while unrolling the panels"),
            "{text}"
        );
        assert!(text.contains("bug in unfold"), "{text}");
        assert_eq!(e.exit_code(), 1);
        let source = std::error::Error::source(&e).expect("the cause is kept");
        assert_eq!(source.to_string(), "facet 3 has no area");
    }

    #[test]
    fn each_kind_has_its_exit_code() {
        let io = Error::Io {
            action: "create".into(),
            path: PathBuf::from("/out"),
            source: std::io::Error::from(std::io::ErrorKind::PermissionDenied),
        };
        assert!(io.to_string().starts_with("cannot create /out: "), "{io}");
        assert_eq!(io.exit_code(), 1);
        assert_eq!(
            Error::Build("panel E1 overlaps itself".into()).exit_code(),
            1
        );
        assert_eq!(Error::Usage("--size".into()).exit_code(), 2);
        let input = InputError::new(Path::new("m.obj"), Location::Line(3), "bad", "fix");
        assert_eq!(Error::from(input).exit_code(), 3);
    }
}
