//! The leaf-resolution operator: every leaf gathers from every link at itself and at its ancestors,
//! with the form factor evaluated for the leaf itself instead of the ancestor's average, and every
//! link sends its source's radiosity weighted by how much of each source leaf's light the link
//! carries, so that the operator conserves energy exactly.
//!
//! A link stored at a coarse receiver hands the same average form factor to every leaf below it; where
//! the point form factor varies over that receiver (near edges and corners that touch the source) the
//! leaves' row sums drift from the truth, and each level of the hierarchy adds its share: in a closed
//! box the corner leaves of an `eps = 0.1` BF solution gathered 1.86 times the light they see. Here
//! the links (which sources interact with which region, and their visibility) are kept, but each leaf
//! gets its own form factor to each of its chain's sources, so its row sum is the point-sampled
//! truth up to receiver quadrature.
//!
//! The source side has the mirror problem. A source split for some receivers and not for others
//! sends its area-mean radiosity along its coarse links, while its children's own links send each
//! child's: a child then delivers its own fraction to some receivers and its parent's average
//! fraction to the rest, which sum to more or less than the light it emits (0.83 to 1.34 of it in a
//! closed room lit by a small bright source, 1 to 2% of the power created or lost). Here each
//! source `S` sends, along all its links, `Σ_y a_y B_y / Σ_y a_y` over its leaves `y`, weighted by
//! `a_y = Σ_L A_y F(y ← R_L) V_L`, the light of `y` that `S`'s links `L` carry to their receivers
//! `R_L` (reciprocity: `A_R F(R ← y) = A_y F(y ← R)`). Each leaf then delivers exactly the fraction
//! of its light that its links cover. Per link, the transfer `τ_L = A_R F(R ← S) V` is the same on
//! both sides: summed over the receiver's leaves and over the source's leaves, taken from the side
//! evaluated exactly (a surface at the other end; the cluster approximation is the other side's),
//! and the other side scaled to it.
//!
//! The operator is solved to convergence with GMRES, starting from the hierarchical solution. It
//! stores one coefficient per (leaf, chain link) in a [`Precision`] (`f32`, or 16 bits for a target
//! error of [`HALF_MIN_TARGET`] or coarser), in chain order (the link is implied), and
//! one weight per (link source, leaf below it); beyond a budget of coefficients the remaining
//! leaves' coefficients are computed again at every application, so that a budget costs time but
//! never changes the answer.
//!
//! The folder holds the operator one step per file, in the order a solve takes them:
//! - `precision.rs`: how a chain coefficient is stored ([`Precision`]: `f32` or a 16-bit
//!   logarithmic code) and its encoding;
//! - `chain.rs`: the unknowns below each element, the links received at each element, and the
//!   chain of links of one unknown with its coefficients `F(unknown ← source) V`;
//! - `weights.rs`: the source side: each link's weights over its source's unknowns, and the form
//!   factors that share a link's transfer among leaves;
//! - `coefficients.rs`: [`LeafCoefficients`] built for a cut (receiver side, source side, each
//!   link's two sides scaled to one transfer), closed in a closed scene, and what each link sends;
//! - `operator.rs`: [`LeafOperator`], which gathers every unknown's irradiance from the
//!   coefficients and applies `I − M`, and [`leaf_operator_entries`], the size it would take.
//!
//! This file holds what the steps share: the budgets and thresholds, and the coefficients' layout.

mod chain;
mod coefficients;
mod operator;
mod precision;
mod reuse;
mod weights;

pub use operator::{LeafOperator, leaf_operator_entries};
pub use precision::{HALF_MIN_TARGET, HALF_ROUNDING, Precision};
pub use reuse::ChainReuse;

use crate::hierarchy::ElementId;
use precision::Stored;

/// Default budget of the leaf-resolution operator's stored coefficients, in bytes (what 40 M
/// coefficients with their link indices in `f64` took before): beyond it the coefficients of the
/// remaining unknowns are recomputed at every application instead of stored
/// ([`LeafCoefficients::for_cut`]): the same operator, bit for bit, only slower.
pub const LEAF_OPERATOR_MAX_BYTES: usize = 480_000_000;

/// Source leaves farther from a receiver than this many times the sum of their bounding radii get
/// their weight from the point form factor at their centre rather than the precise one (the
/// weights only share a link's transfer among the source's leaves).
pub const WEIGHT_FAR_SEPARATION: f64 = 4.0;

/// The coefficients of a [`LeafOperator`]: geometry only (form factors and visibility), so they
/// serve every emission of the same hierarchy and links (the instanced solver keeps them with a
/// level it reuses).
///
/// Each unknown's coefficients along its chain of links (`F(unknown ← source) V`, rounded to
/// `f32`) are stored in chain order for the first [`LeafCoefficients::stored_unknowns`] unknowns,
/// and recomputed, identically, at every application for the rest (beyond the budget the
/// coefficients were built with). What makes the operator conserve energy is kept per link, in
/// `f64`: the receiver side's scale and the source side's weights.
#[derive(Clone, Debug)]
pub struct LeafCoefficients {
    /// Link indices sorted by (receiver, source), and each element's range in it.
    sorted: Vec<u32>,
    range: Vec<(u32, u32)>,
    /// Start of each stored unknown's chain coefficients in `coef` (length stored + 1).
    start: Vec<usize>,
    coef: Stored,
    /// Chain coefficients taken from an earlier level's.
    reused: usize,
    /// Chain coefficients of every unknown, stored or not.
    chain_entries: usize,
    /// Links received inside an unknown (below it, on a coarsened cut): `(link, coefficient)`
    /// ranges per unknown (empty at leaf resolution).
    inside_start: Vec<u32>,
    inside: Vec<(u32, f64)>,
    /// Per link: the factor on its receiver-side coefficients that makes them carry the link's
    /// transfer (and, in a closed scene, the closure factor of its source).
    scale: Vec<f64>,
    /// Per link, the transfer `τ_L` both sides are scaled to (before a closure).
    transfer: Vec<f64>,
    /// Per link, where its source value comes from.
    value: Vec<SourceValue>,
    /// The leaves below each source with weights, once per source (every range of weights of a
    /// source is over the same leaves, in the same order).
    weight_leaf: Vec<ElementId>,
    /// Weights of source leaves: ranges referred to by [`SourceValue`], each with the start of
    /// its source's leaves in `weight_leaf`. Made and summed in `f64`, stored in the chain
    /// coefficients' precision (`f32` in a closed scene, whose closure rescales them): they only
    /// share a link's transfer among its source's leaves, and each link's scale is divided by its
    /// range's sum as stored, so the link sends its transfer whole whatever the rounding. In `f64`
    /// they were a third of a 3,200-leaf canopy's heap peak; in `f32`, 164 of its 623 MB.
    weight: precision::Stored,
    /// Sources with shared weights: `(source, start, end, leaves)` into `weight`, and the start
    /// of its leaves in `weight_leaf`.
    shared: Vec<(ElementId, usize, usize, usize)>,
    /// Built for a closed scene (with the closure applied).
    closed: bool,
    /// Smallest and largest closure factor applied ([`LeafCoefficients::closure`]).
    closure: (f64, f64),
    /// Per link, the closure factor on its transfer less 1 (empty in an open scene).
    closure_change: Vec<f32>,
}

/// Smallest closure factor of one unknown: delivering more than twice its light means something
/// other than sampling noise, and is not corrected beyond this.
pub const CLOSURE_MIN: f64 = 0.5;
/// Largest change `|factor − 1|` of the closure taken as correcting sampled visibility and
/// quadrature ([`LeafCoefficients::closure_changes`], counted in the error estimate): those are
/// 1e-5 to 1e-3 (CIE 171 5.8: 5e-4; a 5 cm lamp in a 4 m room: 1e-4). Larger factors make up for
/// an unknown partly covered by something standing on it ([`CLOSURE_MAX`]), which is geometry,
/// not error: counting them kept the 1990 room with partitions refining to 8.8M links.
pub const CLOSURE_NOISE_MAX: f64 = 0.02;
/// Largest closure factor of one unknown. An unknown partly covered by something standing on it (a
/// floor piece under a chair's foot) is sampled over its whole area but sends light from its
/// uncovered part only, so its links deliver that part's share of its light; the factor then makes
/// up for the cover (4 for a piece three quarters covered). Beyond this the unknown is taken as
/// covered whole (it also receives next to nothing).
pub const CLOSURE_MAX: f64 = 1000.0;

/// What a link sends: its source's radiosity, weighted over the source's leaves.
#[derive(Clone, Copy, Debug)]
enum SourceValue {
    /// The source is a leaf: its radiosity.
    Leaf(ElementId),
    /// The link's own weights (`start..end` of `weight`, summing to 1), and the start of its
    /// source's leaves in `weight_leaf`.
    Own(u32, u32, u32),
    /// The weights shared by the source's far links (entry of `shared`).
    Shared(u32),
}

/// Sources whose leaf weights are made at a time when the leaf operator is built (in parallel
/// within a chunk): their weights are held twice until copied into place.
pub const WEIGHT_CHUNK: usize = 4096;

/// Most weights made at a time (in `f64`, in parallel within a chunk of sources, before they are
/// copied into place), unless one source has more: a chunk of [`WEIGHT_CHUNK`] sources of a
/// 3,200-leaf canopy, the clusters near its top with thousands of leaves below them each, held
/// 452 MB of its 703 MB heap peak.
pub const WEIGHT_CHUNK_ENTRIES: usize = 1 << 21;

/// Links nearer than this (centre distance over the sum of the bounding radii) weight their
/// source's leaves by their own kernel; farther links share one set of weights per source (the
/// kernel varies little over a far source).
pub const OWN_WEIGHTS_SEPARATION: f64 = 4.0;

/// Chain coefficients computed at a time while the receiver totals of unstored unknowns are
/// summed (a bounded buffer, filled in parallel, summed in order).
const STREAM_BATCH_ENTRIES: usize = 1 << 20;
