//! [`PathError`]: everything that can go wrong with a path file, positioned.

use cov_core::CovError;

/// Everything that can go wrong with a path file: a position in the file when there is one.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PathError {
    /// Malformed RON, an unknown operator or parameter, a bad value: with its position.
    #[error("{file}:{line}:{col}: {message}")]
    Parse {
        /// File name (or `<string>`).
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        col: usize,
        /// What is wrong.
        message: String,
    },
    /// A path that parsed but does not fit together (a declared layout that lacks an axis
    /// an operator or the source needs), with the position of the step when it is known.
    #[error("{file}:{}{message}", position(at))]
    Invalid {
        /// File name (or `<string>`).
        file: String,
        /// Line and column of the offending step.
        at: Option<(usize, usize)>,
        /// What is wrong.
        message: String,
    },
    /// A path that failed while it was traced (overflow, no transport …): the typed
    /// error, with the position of the failing step when it is known.
    #[error("{file}:{}{source}", position(at))]
    Eval {
        /// File name (or `<string>`).
        file: String,
        /// Line and column of the failing step.
        at: Option<(usize, usize)>,
        /// What went wrong ([`CovError::Step`] names the step and operator).
        source: Box<CovError>,
    },
    /// The file could not be read.
    #[error("{file}: {message}")]
    Io {
        /// File name.
        file: String,
        /// The I/O error.
        message: String,
    },
}

fn position(at: &Option<(usize, usize)>) -> String {
    at.map(|(l, c)| format!("{l}:{c}: "))
        .unwrap_or_else(|| " ".into())
}

impl PathError {
    /// The file the error is attributed to.
    pub fn file(&self) -> &str {
        match self {
            PathError::Parse { file, .. }
            | PathError::Invalid { file, .. }
            | PathError::Eval { file, .. }
            | PathError::Io { file, .. } => file,
        }
    }

    /// The same error attributed to `name`.
    pub fn in_file(mut self, name: &str) -> Self {
        match &mut self {
            PathError::Parse { file, .. }
            | PathError::Invalid { file, .. }
            | PathError::Eval { file, .. }
            | PathError::Io { file, .. } => *file = name.to_string(),
        }
        self
    }
}
