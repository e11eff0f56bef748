//! Errors of the scene step: every message names the file, the place (line or face) and the reason.
//! A reason that is itself an error (the operating system's) is the error's `source`, not part of
//! its message, so a front end printing the chain of causes prints it once.

use std::path::PathBuf;

/// A scene that cannot be loaded or is not valid input for a solve.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read (the reason is the source).
    #[error("{}: cannot read file", path.display())]
    Io {
        /// File that failed.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// A syntax error at a given line.
    #[error("{}:{line}: {msg}", path.display())]
    Parse {
        /// File.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        msg: String,
    },
    /// A coordinate that is NaN or infinite.
    #[error("{}:{line}: non-finite coordinate in {what}", path.display())]
    NonFinite {
        /// File.
        path: PathBuf,
        /// 1-based line number (0 when unknown).
        line: usize,
        /// The entity (vertex, transform ...).
        what: String,
    },
    /// A material whose diffuse reflectance is outside [0, 1) or whose emission is negative or not finite.
    #[error("{}: material `{material}`: {msg}", path.display())]
    Material {
        /// File.
        path: PathBuf,
        /// Material name.
        material: String,
        /// What is wrong.
        msg: String,
    },
    /// Nothing emits light (use `allow_dark` to accept it).
    #[error("{}: no emitter: no material has a positive emission (Ke / ed); pass --allow-dark to solve a dark scene", path.display())]
    NoEmitter {
        /// File.
        path: PathBuf,
    },
    /// No usable polygon in the scene.
    #[error("{}: the scene has no usable polygon", path.display())]
    Empty {
        /// File.
        path: PathBuf,
    },
    /// The file extension is not one the loader knows.
    #[error("{}: unknown scene format (expected .obj or .mgf)", path.display())]
    UnknownFormat {
        /// File.
        path: PathBuf,
    },
}
