//! Error type shared by the library: every configuration error names the file and the field.

use std::path::{Path, PathBuf};

/// Errors returned by railforce's library functions.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A configuration value is wrong: the message names the file, the field and the reason.
    #[error("{}: {field}: {message}", file.display())]
    Config {
        /// File the value came from (or `<memory>` for values built in code).
        file: PathBuf,
        /// Dotted path of the offending field, e.g. `section[2].radius_m`.
        field: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// A file could not be parsed at all (syntax error, unknown key, wrong type).
    #[error("{}: {message}", file.display())]
    Parse {
        /// File that failed to parse.
        file: PathBuf,
        /// Parser message, with line and column where the parser gives them.
        message: String,
    },
    /// Reading or writing a file failed. The message is the path and the OS's reason, once
    /// (the I/O error is not chained as a source, so error reports do not repeat it).
    #[error("{}: {}", path.display(), reason(error))]
    Io {
        /// Path involved.
        path: PathBuf,
        /// Underlying error.
        error: std::io::Error,
    },
    /// A query or computation went outside what the model supports.
    #[error("{0}")]
    Domain(String),
    /// A wheel left its rail in a run (flange climb, lift or lateral shift past the limits,
    /// or Nadal's limit held where the run was told to stop on it): the message names the
    /// time, the place and the wheel.
    #[error("{0}")]
    Derailment(String),
}

impl Error {
    /// Builds a [`Error::Config`] error.
    pub fn config(file: &Path, field: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Config {
            file: file.to_path_buf(),
            field: field.into(),
            message: message.into(),
        }
    }

    /// Wraps an I/O error with the path it concerns.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io {
            path: path.to_path_buf(),
            error: source,
        }
    }
}

/// The OS's reason in words people use: "no such file or directory", without the error code.
fn reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file or directory".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => e.to_string(),
    }
}

/// Result alias used throughout the crate.
pub type Result<T> = std::result::Result<T, Error>;
