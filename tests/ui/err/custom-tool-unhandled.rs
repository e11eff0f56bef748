// A tool from user code: the macro cannot see its answers, rustc proves the match exhaustive.
use radiosity::oracle;
use radiosity::oracle::Tool;
use radiosity::refine::LinkCtx;

radiosity::answer_enum! {
    pub enum Kind { Surfaces, Clusters, Mixed }
}

pub struct PairKind;

impl Tool for PairKind {
    type Answer = Kind;
    fn ask(&self, _: &mut LinkCtx<'_>) -> Kind {
        Kind::Mixed
    }
}

oracle! {
    crate = ::radiosity;
    oracle ByKind {
        start => kind;
        kind: PairKind { Surfaces => link, Clusters => subdivide_both }
    }
}

fn main() {}
