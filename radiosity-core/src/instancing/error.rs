//! Errors of the instancing step: every message names the file, the line when known, and the reason.
//! A reason that is itself an error (the operating system's, a prototype file's) is the error's
//! `source`, not part of its message, so a front end printing the chain of causes prints it once.

use crate::scene::SceneError;
use std::path::PathBuf;

/// A scene file with instances that cannot be loaded, written, or solved.
#[derive(Debug, thiserror::Error)]
pub enum InstancingError {
    /// A file could not be read or written (the reason is the source).
    #[error("{}: {what}", path.display())]
    Io {
        /// File that failed.
        path: PathBuf,
        /// What was being done (`cannot read file`, `cannot write file` ...).
        what: String,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// A problem located at a line of a scene file (syntax, unknown name, cycle, singular transform).
    #[error("{}:{line}: {msg}", path.display())]
    At {
        /// File.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        msg: String,
    },
    /// A prototype's OBJ file is invalid (the source names its file, line and reason).
    #[error("{}:{line}: prototype `{prototype}`", path.display())]
    Prototype {
        /// Scene file naming the prototype.
        path: PathBuf,
        /// Line of the prototype's `obj = ...` entry.
        line: usize,
        /// Prototype name.
        prototype: String,
        /// The OBJ error (boxed: it is large, and errors travel through every `Result`).
        source: Box<SceneError>,
    },
    /// A material, or a scene, that the builder rejected.
    #[error(transparent)]
    Scene(Box<SceneError>),
    /// A cached property file exists but cannot be decoded.
    #[error("{}: corrupt property cache entry: {msg}", path.display())]
    Cache {
        /// Cache file.
        path: PathBuf,
        /// Decoder message.
        msg: String,
    },
    /// A distributed solve failed: a message between processes that cannot be decoded, or a
    /// process that failed (the message names it).
    #[error("distributed solve: {0}")]
    Distributed(String),
}

impl From<SceneError> for InstancingError {
    fn from(e: SceneError) -> InstancingError {
        InstancingError::Scene(Box::new(e))
    }
}

impl InstancingError {
    /// An error at `line` of `path`.
    #[must_use]
    pub fn at(path: &std::path::Path, line: usize, msg: impl Into<String>) -> InstancingError {
        InstancingError::At { path: path.to_owned(), line, msg: msg.into() }
    }

    /// An I/O error on `path`.
    #[must_use]
    pub fn io(path: &std::path::Path, what: &str, source: std::io::Error) -> InstancingError {
        InstancingError::Io { path: path.to_owned(), what: what.to_owned(), source }
    }
}
