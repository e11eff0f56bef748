// The BF graph written in user code, through the `radiosity` facade.
use radiosity::oracle;
use radiosity::refine::Oracle;

oracle! {
    crate = ::radiosity;

    /// The classic BF refiner.
    pub oracle Bf {
        params { eps: f64 = 0.01 in 0.0..=1.0, min_area: f64 = 0.0 }
        start => facing;
        facing: Facing { No => stop, Yes => near }
        near: ClusterTooNear { Yes => size, No => energy }
        energy: BfAbove(eps) { No => link, Yes => size }
        size: CanSubdivide(min_area) {
            Neither => link,
            Emitter => subdivide_emitter,
            Receiver => subdivide_receiver,
            Both => larger,
        }
        larger: Larger { Emitter => subdivide_emitter, Receiver => subdivide_receiver }
    }
}

fn main() {
    let mut params = BfParams::default();
    params.set("eps", 0.05).unwrap();
    assert!(params.set("eps", 2.0).is_err());
    assert!(params.set("nope", 1.0).is_err());
    let bf = Bf::new(params);
    assert_eq!(bf.name(), "Bf");
    assert_eq!(Bf::<radiosity::oracle::NoProbe>::GRAPH.nodes.len(), 5);
}
