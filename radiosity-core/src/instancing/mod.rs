//! Hierarchical instantiation: prototypes, instances, cached radiative properties, depth-first solve.
//!
//! Data flow, one line per step:
//! - [`load`] (TOML scene file, prototypes from OBJ or generated) → [`InstancedScene`]
//! - [`flatten()`] → a plain [`crate::scene::Scene`] for the reference ("full") solve
//! - [`properties`]: per prototype τ(ω), a(ω) = (1 − τ(ω))·A_box(ω) and the escape albedo, cached on
//!   disk by content hash
//! - [`solve_instanced`]: closed instances as proxies, then depth-first opening, streaming polygons
//! - [`plant`]: procedural poplar-like trees and forests; [`write_scene`] writes them out
//!
//! # Scene file
//! ```toml
//! name = "two twigs"              # optional
//! root = "tree"                   # optional: the scene is this prototype; otherwise the
//!                                 # top-level obj / box / polygon / instance entries form it
//! [[material]]
//! name = "leaf"                   # matched against `usemtl` names of prototype OBJ files
//! reflectance = [0.25, 0.45, 0.15]  # or one number
//! transmittance = 0.2             # optional diffuse transmittance: makes it two-sided
//! emission = 0.0                  # optional, W/m²
//! two_sided = true                # optional
//!
//! [[prototype]]
//! name = "twig"
//! obj = "twig.obj"                # relative to the scene file
//! materials = { leaf = "leaf" }   # optional: OBJ material name → scene material
//! [[prototype.box]]               # generated geometry: min, max, material, inward
//! [[prototype.polygon]]           # material, vertices = [[x, y, z], ...]
//! [[prototype.instance]]          # of = "other prototype", then either
//! of = "leaf_pair"                #   matrix = [12 numbers, row-major 3×4 | 16, row-major 4×4]
//! translate = [0, 0, 0.3]         #   or translate / rotate (degrees about x, y, z) / scale,
//! rotate = [0, 30, 77]            #   composed as translate · rotate · scale
//! scale = 0.8
//!
//! units = "photometric"           # optional: lm, cd, lx (default "radiometric": W, W/m²)
//! [[luminaire]]                   # a photometric file placed in the scene (photometric units)
//! ies = "downlight.ies"           # or ldt = "downlight.ldt", relative to the scene file
//! position = [2.0, 2.0, 2.9]
//! aim = [0.0, 0.0, -1.0]          # photometric nadir (γ = 0); default −z
//! rotate = 0.0                    # degrees about the aim, turning the C = 0 plane
//! multiplier = 1.0
//! [[grid]]                        # optional, repeatable: calculation points (points::GridSpec)
//! name = "work"                   #   grid_work.csv: origin + s·u + t·v, points in the centres
//! origin = [0.5, 0.5, 0.8]        #   of cells at most `spacing` wide, half a cell in from the
//! u = [3.0, 0.0, 0.0]             #   edges; `normal` optional (default u × v)
//! v = [0.0, 3.0, 0.0]
//! spacing = 0.25
//! normal = [0.0, 0.0, 1.0]
//! ```
//! A file with luminaires or photometric units is flattened and solved as a plain scene (see
//! [`crate::luminaire`]). Instances nest to any depth; a cycle, a singular transform, a missing OBJ file or a syntax error
//! is reported as `file:line: reason`.
//!
//! # Two-sided surfaces
//! A two-sided material's side has radiosity `ρ·H(same side) + t·H(other side)`. The plain solver
//! only knows one-sided surfaces, so the flattened scene and the local problems of the instanced
//! solver represent a two-sided polygon as two back-to-back one-sided polygons (reflection on both
//! sides exact, transmittance dropped); the prototype properties ([`properties`], random-walk method)
//! account for the transmittance.

pub mod auto;
pub mod balance;
pub mod bench;
pub mod caster;
mod error;
pub mod face_transfer;
pub mod flatten;
pub mod format;
pub mod model;
pub mod obj_mesh;
pub mod output;
pub mod plant;
pub mod poplar;
pub mod properties;
pub mod solver;
pub mod write;

pub use auto::{AutoOptions, AutoReport, AutoResult, auto_instance};
pub use caster::InstanceCaster;
pub use error::InstancingError;
pub use flatten::{FlattenOptions, flatten, flatten_prototype};
pub use format::{Lighting, LuminaireSpec, bands, load, load_with_lighting, parse, parse_with_lighting};
pub use model::{Instance, InstancedScene, LocalPolygon, Prototype, PrototypeId, Transform};
pub use output::{StreamedOutput, StreamedSummary};
pub use plant::{ForestParams, TreeParams, generate_forest, generate_tree};
pub use solver::{
    InstanceLevels, InstancedConfig, InstancedStats, Leaf, LevelReuse, PolygonInfo, PolygonMeans, ProxyEmission, RadiositySink,
    distributed, solve_full, solve_instanced,
};
pub use write::write_scene;
