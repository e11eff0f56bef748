//! MGF (Materials and Geometry Format) reader. Placeholder: being written.

use super::{Scene, SceneError};
use std::path::Path;

/// Loads an MGF file (with its includes).
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    Err(SceneError::UnknownFormat { path: path.to_owned() })
}
