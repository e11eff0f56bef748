// A tool defined in user code, with its own answer enum: rustc checks its arms.
use radiosity::oracle;
use radiosity::oracle::Tool;
use radiosity::refine::LinkCtx;

radiosity::answer_enum! {
    pub enum Kind { Surfaces, Clusters, Mixed }
}

pub struct PairKind;

impl Tool for PairKind {
    type Answer = Kind;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> Kind {
        match (ctx.emitter_element().is_cluster(), ctx.receiver_element().is_cluster()) {
            (false, false) => Kind::Surfaces,
            (true, true) => Kind::Clusters,
            _ => Kind::Mixed,
        }
    }
}

oracle! {
    crate = ::radiosity;
    pub oracle ByKind {
        start => kind;
        kind: PairKind { Surfaces => link, Clusters | Mixed => subdivide_both }
    }
}

fn main() {
    let _ = ByKind::new(ByKindParams::default());
}
