// A shared sub-graph used by two oracles, a node reached from several arcs, a computed parameter.
use radiosity::oracle;

oracle! {
    crate = ::radiosity;

    shared split {
        size: CanSubdivide(0.0) {
            Neither => link,
            Emitter => subdivide_emitter,
            Receiver => subdivide_receiver,
            Both => subdivide_both,
        }
    }

    pub oracle Vis {
        params {
            rays: u32 = 4 in 1..=64,
            small: f64 = computed |ctx| 0.01 * ctx.receiver_element().area,
        }
        use split;
        start => visible;
        visible: RayVisibility(rays) {
            Invisible | ProbablyInvisible => stop,
            Visible | ProbablyVisible => tiny,
            Partial | ProbablyPartial | TooComplex => size,
        }
        tiny: ProjectedAreaBelow(small) { Yes => link, No => size }
    }

    pub oracle Near {
        use split;
        start => near;
        near: ClusterTooNear { Yes => size, No => link }
    }
}

fn main() {
    let _ = Vis::new(VisParams::default());
    let _ = Near::new(NearParams::default());
}
