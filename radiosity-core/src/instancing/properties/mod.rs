//! Radiative properties of a prototype, seen from outside as one closed object, and their on-disk
//! cache keyed by the prototype's content.
//!
//! For each direction ω of a Fibonacci sphere (ω points toward the light):
//! - the directional transmittance τ(ω): the fraction of parallel rays travelling along −ω that cross
//!   the prototype's bounding box without meeting a polygon (stratified rays over the box's shadow);
//! - the box's projected area `A_box(ω)` (exact) and the effective projected area
//!   `a(ω) = (1 − τ(ω))·A_box(ω)`;
//! - the escape albedo α(ω): the fraction of the power intercepted from a unit irradiance along ω
//!   that leaves the prototype after any number of interreflections (the rest is absorbed), and the
//!   phase value `P(ω) = π·α(ω)·a(ω) / ∫a(ω′)dω′`: the outgoing radiosity per unit projected area
//!   for unit incoming irradiance, under the approximation that the outgoing radiance is uniform
//!   over directions.
//!
//! The albedo comes from a [`PhaseMethod`]: a seeded random walk through the prototype (handles
//! two-sided surfaces with transmittance exactly), or a local hierarchical radiosity solution of the
//! prototype lit by a large distant emitter ([`crate::pipeline::run`] with [`crate::refine::ClassicBf`];
//! one-sided and two-sided-as-pairs surfaces, no transmittance).
//!
//! # Layout
//! One file per step of getting a prototype's properties: `settings` (how they are sampled and
//! how the albedo is computed), `entry` (what is stored per prototype), `key` (the content hash
//! and the cache key), `sampling` (directions, projected areas, the sampling geometry), `measure`
//! (τ and the random-walk albedo, ray by ray), `radiosity` (the albedo from a local radiosity
//! solve), `cache` (the entries on disk).

mod cache;
mod entry;
mod key;
mod measure;
mod radiosity;
mod sampling;
mod settings;

pub use cache::{CacheOutcome, PropertyCache};
pub use entry::RadiativeProperties;
pub use key::{CACHE_VERSION, cache_key, content_hashes};
pub use measure::{MAX_BOUNCES, RAY_OFFSET_REL, compute, compute_flat};
pub use radiosity::DIRECT_SAMPLES_PER_SIDE;
pub(super) use sampling::{basis, cosine_dir_from};
pub use sampling::{box_projected_area, sphere_directions};
pub use settings::{PhaseMethod, PropertyConfig};
