//! Hierarchical radiosity with clustering, refinement oracles and visibility by ray casting.
//!
//! The data flows one way, one module per step:
//! - [`scene`]: load and validate OBJ / MGF / the embedded Cornell box → [`scene::Scene`]
//! - [`analysis`]: what the scene needs (visibility? colour?) → [`analysis::SceneTraits`]
//! - [`hierarchy`]: clusters over the input polygons, surfaces subdivided lazily → [`hierarchy::Hierarchy`]
//! - [`formfactor`]: point-to-polygon analytic form factors, receiver quadrature, isotropic clusters
//! - [`visibility`]: ray casting against a BVH of the input triangles
//! - [`refine`]: the oracle decides per link: link here or subdivide → links
//! - [`solve`]: gather, push-pull, GMRES on the hierarchical operator → radiosity per element
//! - [`output`]: `image.png`, `solution.ply`, `solution.glb`, `patches.csv`, `stats.json`
//! - [`points`]: irradiance at calculation points, gathered from the solution → `points.csv`
//! - [`lab`]: experiments on oracles that run whole solves (benchmark, visibility study, `explain`)
//! - [`canopy`]: random canopies of black leaves for validation against Beer's law
//! - [`photometry`]: luminous intensity distributions of luminaires (IES LM-63, EULUMDAT)

pub mod analysis;
pub mod canopy;
pub mod daylight;
pub mod formfactor;
pub mod geom;
pub mod hierarchy;
pub mod instancing;
pub mod lab;
pub mod light;
pub mod luminaire;
pub mod oracle;
pub mod output;
pub mod photometry;
pub mod pipeline;
pub mod points;
pub mod refine;
pub mod scene;
pub mod solve;
pub mod validation;
pub mod visibility;
