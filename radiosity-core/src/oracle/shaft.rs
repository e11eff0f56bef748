//! The shaft oracle (Haines & Wallace shafts), declared with `oracle!`: the BF oracle
//! ([`super::bf`]) with the link's shaft deciding visibility where it can. A link whose shaft one
//! occluder blocks whole is stopped without a ray; one whose shaft no object enters is fully
//! visible, so partial visibility cannot err and no ray is cast for it; only links whose shaft
//! holds candidate occluders go on to [`crate::oracle::tools::PartialVisibility`], whose rays are
//! cast against those candidates only. The energy questions are BF's, asked before the shaft:
//! a link whose whole transfer is within the threshold needs no shaft at all. Its tools
//! ([`crate::oracle::tools::ShaftClassify`]) are built-ins, so the DAG runtime runs the same graph
//! (`radiosity oracle explain shaft`); they declare that they need shaft culling
//! ([`crate::refine::Needs::SHAFTS`]), so [`crate::pipeline::run`] turns OBB shafts on when the
//! configuration asks for plain rays.
//!
//! The paper's own criterion, the form factor error bound `B_S · (F_max − F_min)` with `F_min = 0`
//! when a candidate may occlude, is the tool [`crate::oracle::tools::ShaftFfError`]: it bounds
//! how the point form factor varies over the receiver, which the leaf-resolution solve already
//! evaluates leaf by leaf, and relative to each receiver's irradiance it refines the Cornell box to
//! 4.3 M links where BF needs 64,000, so the shipped graph does not use it.

oracle_macros::oracle! {
    crate = crate;

    /// The shaft oracle: BF's energy questions, then the shaft classification for visibility.
    pub oracle ShaftOracle {
        params { eps: f64 = 0.01 in 0.0..=1.0, min_area: f64 = 0.0 in 0.0..=1e300 }
        start => facing;
        facing: Facing { No => stop, Yes => near }
        near: ClusterTooNear { Yes => size, No => transfer }
        transfer: BfAbove(eps) { No => link, Yes => shaft }
        shaft: ShaftClassify { Invisible => stop, Visible => open, Partial => cluster }
        open: ClusterError(eps) { Above => size, Below => open_variation }
        open_variation: SourceVariation(eps) { Above => open_source, Below => link }
        open_source: CanSubdivide(min_area) {
            Neither => link,
            Emitter => subdivide_emitter,
            Receiver => link,
            Both => subdivide_emitter,
        }
        cluster: ClusterError(eps) { Above => size, Below => variation }
        variation: SourceVariation(eps) { Above => source, Below => shadow }
        source: CanSubdivide(min_area) {
            Neither => link,
            Emitter => subdivide_emitter,
            Receiver => shadow,
            Both => subdivide_emitter,
        }
        shadow: PartialVisibility(eps) { Above => size, Below => link }
        size: CanSubdivide(min_area) {
            Neither => link,
            Emitter => subdivide_emitter,
            Receiver => subdivide_receiver,
            Both => first,
        }
        first: SplitFirst { Emitter => subdivide_emitter, Receiver => subdivide_receiver }
    }
}
