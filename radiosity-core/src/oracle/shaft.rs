//! The shaft oracle (Haines & Wallace shafts, as the shaft paper uses them), declared with `oracle!`:
//! build the link's shaft; if one occluder blocks it whole, stop; if any candidate occluder enters
//! it, the smallest form factor is taken as 0; if the form factor error `B_S · (F_max − F_min)`
//! exceeds `eps · B_ref`, subdivide; otherwise link (the driver then computes the visibility by
//! rays against the shaft's candidates only). Its tools ([`crate::oracle::tools::ShaftClassify`],
//! [`crate::oracle::tools::ShaftFfError`]) are built-ins, so the DAG runtime runs the same graph
//! (`radiosity oracle explain shaft`); they declare that they need shaft culling
//! ([`crate::refine::Needs::SHAFTS`]), so [`crate::pipeline::run`] turns OBB shafts on when the
//! configuration asks for plain rays.
//!
//! One step comes before the shaft: when `B_S · F_max` alone (the error with `F_min = 0`, the BF
//! criterion [`crate::oracle::tools::BfAbove`]) is within the threshold, no classification can make
//! the link's error larger, so the link is stored without one. The decisions are the paper's except
//! for a link below the threshold that one occluder blocks whole: it goes to the driver as a link,
//! which drops it when all its segments come out blocked, instead of being stopped by the shaft.
//! Measured (callgrind, one thread, whole solve): the step takes the duplex from 1.22 G to 0.90 G
//! instructions (4,681 → 4,684 links, solutions within 1.4e-6 of the largest radiosity) and
//! sj-geometry from 0.56 G to 0.42 G (links unchanged).

oracle_macros::oracle! {
    crate = crate;

    /// The shaft oracle: links whose error is within the threshold even with `F_min = 0` first,
    /// then the shaft classification, form factor error bounds from it.
    pub oracle ShaftOracle {
        params { eps: f64 = 0.01 in 0.0..=1.0, min_area: f64 = 0.0 in 0.0..=1e300 }
        start => facing;
        facing: Facing { No => stop, Yes => bound }
        bound: BfAbove(eps) { No => link, Yes => shaft }
        shaft: ShaftClassify { Invisible => stop, Visible => error, Partial => error }
        error: ShaftFfError(eps) { Below => link, Above => size }
        size: CanSubdivide(min_area) {
            Neither => link,
            Emitter => subdivide_emitter,
            Receiver => subdivide_receiver,
            Both => first,
        }
        first: SplitFirst { Emitter => subdivide_emitter, Receiver => subdivide_receiver }
    }
}
