//! MGF (Materials and Geometry Format 2.0) reader, following the reference parser mgflib as used by
//! Radiance and RenderPark.
//!
//! Supported entities:
//! - `#` comments; a trailing backslash continues a line.
//! - Vertices: `v name =`, `v name = other`, `v name`, `v`; `p x y z`; `n nx ny nz`. Vertices are
//!   transformed when a face uses them, by the transform then in force.
//! - Faces: `f v1 v2 v3 ...` (CCW about the front normal; more than 4 vertices, or non-planar or
//!   concave quads, are triangulated by the [`SceneBuilder`](super::SceneBuilder)), and `fh` (holes
//!   after `-`, joined to the outer contour by seams to the nearest vertex).
//! - Primitives tessellated as mgflib does with `quarter_circle_divisions` (RenderPark's
//!   `-nqcdivs`, default 4): `sph`, `cyl`, `cone`, `ring`, `torus`, `prism`; a negative radius makes
//!   an inward-facing surface (table in `primitives.rs`).
//! - Objects: `o name` ... `o`. A face's group is the path of open objects joined with `/`
//!   (`building/room/desk`), `(root)` outside every object. Array instances are objects `a0`, `a1`
//!   ... (`a0.1` for two `-a`), as mgflib names them.
//! - Transforms: `xf args` ... `xf` (options in `xform.rs`), with `-a n` arrays re-reading the enclosed
//!   entities once per instance, and mirrors reversing vertex order. A transform still open at the
//!   end of its file is closed there with a warning.
//! - Includes: `i file [xf args]`, relative to the including file; the arguments transform the
//!   included file (read once per array instance). A missing file is [`SceneError::Io`]; an include
//!   cycle is a [`SceneError::Parse`] error.
//! - Colours `c`, `cxy`, `cspec`, `cct`, `cmix` and materials `m`, `rd`, `td`, `ed`, `sides`
//!   (`material.rs` describes the conversion to RGB reflectance and W/m² emission); `rs`, `ts` and `ir`
//!   are checked and ignored (specular parts are dropped).
//! - Anything else (including `ies`) is skipped with one counted warning per entity kind.
//!
//! Malformed numbers, wrong argument counts, undefined vertices / colours / materials and illegal
//! values (zero radii, chromaticities outside the triangle ...) are [`SceneError::Parse`] errors
//! naming the file and line.

mod color;
mod contexts;
mod holes;
mod lines;
mod material;
mod primitives;
mod reader;
mod xform;

#[cfg(test)]
mod tests;

use super::{Scene, SceneError};
use std::path::Path;

/// RenderPark's default number of divisions per quarter circle (`-nqcdivs 4`).
pub const DEFAULT_QUARTER_CIRCLE_DIVISIONS: u32 = 4;

/// How curved primitives are tessellated and how `sides` is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MgfOptions {
    /// Divisions per quarter circle for `sph`, `cyl`, `cone`, `ring` and `torus` (at least 1;
    /// RenderPark's `-nqcdivs`). With n divisions a sphere becomes 2·4n triangles and (2n − 2)·4n
    /// quads, a cylinder 4n quads.
    pub quarter_circle_divisions: u32,
    /// Every surface is one-sided whatever its material's `sides` says (RenderPark's default,
    /// `-force-onesided`). When false, materials are two-sided unless they say `sides 1` (MGF's
    /// default is two-sided). Transmitting materials are always two-sided.
    pub force_one_sided: bool,
}

impl Default for MgfOptions {
    fn default() -> MgfOptions {
        MgfOptions { quarter_circle_divisions: DEFAULT_QUARTER_CIRCLE_DIVISIONS, force_one_sided: true }
    }
}

/// Loads an MGF file (with its includes) with the default [`MgfOptions`].
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    load_with(path, &MgfOptions::default())
}

/// Loads an MGF file (with its includes).
pub fn load_with(path: &Path, options: &MgfOptions) -> Result<Scene, SceneError> {
    reader::Reader::new(path, *options).read(path, None)
}

/// Loads MGF text; `path` names it in messages and locates relative includes.
pub fn load_str(text: &str, path: &Path, options: &MgfOptions) -> Result<Scene, SceneError> {
    reader::Reader::new(path, *options).read(path, Some(text))
}
