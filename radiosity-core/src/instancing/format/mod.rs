//! The scene file with instances (TOML). Reading: [`load`] / [`parse`]; the layout is documented in
//! the module [`crate::instancing`].
//!
//! # Layout
//! One file per part of reading a scene file: `spec` (the entries a file holds, as read, and the
//! transform an instance entry describes), `read` (the whole file: materials, prototypes, root,
//! grids, luminaires, into an [`InstancedScene`](crate::instancing::InstancedScene) and its
//! [`Lighting`]), `prototype` (one prototype's OBJ file, inline geometry and instances),
//! [`bands`] (named bands and daylight, `[site]`, `[sun]`, `[sky]`; also reachable as
//! `crate::instancing::bands`, its path before it joined this folder).

pub mod bands;
mod prototype;
mod read;
mod spec;

pub use read::{Lighting, TOP_LEVEL_NAME, load, load_with_lighting, parse, parse_with_lighting};
pub use spec::{BoxSpec, ColorSpec, InstanceSpec, LuminaireSpec, MaterialSpec, PolygonSpec, ScaleSpec, instance_transform};
