//! A user-written refinement oracle: BF with a visibility branch and a custom tool, declared with
//! `oracle!`, solved on the Cornell box with `radiosity::pipeline::run`, then run again
//! instrumented to print per-node statistics.
//!
//! Run with `cargo run --release --example custom_oracle`.

use radiosity::oracle;
use radiosity::oracle::{NoProbe, Recorder, Tool};
use radiosity::pipeline::{self, Config};
use radiosity::refine::{BfHand, LinkCtx};

radiosity::answer_enum! {
    /// How far apart the two elements are, relative to their sizes.
    pub enum Separation {
        /// Nearer than the threshold: subdivide.
        Near,
        /// Far enough to link.
        Far,
    }
}

/// A custom tool: is the centre distance above `factor` times the sum of the bounding radii?
pub struct Separated(pub f64);

impl Tool for Separated {
    type Answer = Separation;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> Separation {
        let (s, r) = (ctx.emitter_element(), ctx.receiver_element());
        if (s.center - r.center).length() > self.0 * (s.radius + r.radius) { Separation::Far } else { Separation::Near }
    }
}

oracle! {
    crate = ::radiosity;

    shared split {
        size: CanSubdivide(min_area) {
            Neither => link,
            Emitter => subdivide_emitter,
            Receiver => subdivide_receiver,
            Both => larger,
        }
        larger: Larger { Emitter => subdivide_emitter, Receiver => subdivide_receiver }
    }

    /// BF that refines partly occluded near pairs more finely: a cheap 4-ray classification
    /// decides whether a near pair uses a tighter threshold.
    pub oracle ShadowBf {
        params {
            eps: f64 = 0.01 in 0.0..=1.0,
            shadow_eps: f64 = 0.002 in 0.0..=1.0,
            rays: u32 = 4 in 1..=64,
            min_area: f64 = 0.0,
        }
        use split;
        start => facing;
        facing: Facing { No => stop, Yes => near }
        near: ClusterTooNear { Yes => size, No => distance }
        distance: Separated(3.0) { Far => energy, Near => visible }
        visible: RayVisibility(rays) {
            Invisible | ProbablyInvisible => stop,
            Visible | ProbablyVisible | TooComplex => energy,
            Partial | ProbablyPartial => shadow,
        }
        energy: BfAbove(eps) { No => link, Yes => size }
        shadow: BfAbove(shadow_eps) { No => link, Yes => size }
    }
}

fn main() {
    let scene = radiosity::scene::cornell_box();
    let config = Config::default();
    let hand = pipeline::run(&scene, &BfHand::default(), &config, &|_| {});
    let custom = pipeline::run(&scene, &ShadowBf::new(ShadowBfParams::default()), &config, &|_| {});
    println!("hand-written BF: {} links, refinement {:.3} s", hand.links.len(), hand.timings.refine);
    println!("ShadowBf:        {} links, refinement {:.3} s", custom.links.len(), custom.timings.refine);

    let graph = ShadowBf::<NoProbe>::GRAPH;
    let instrumented = ShadowBf::with_probe(ShadowBfParams::default(), Recorder::new(graph.nodes.len()));
    let _ = pipeline::run(&scene, &instrumented, &config, &|_| {});
    print!("{}", radiosity::oracle::runtime::format_stats(&instrumented.probe.stats(&graph)));
}
