// A tool from user code answered with a variant its enum does not have: rustc reports it at the arm.
use radiosity::oracle;
use radiosity::oracle::Tool;
use radiosity::refine::LinkCtx;

radiosity::answer_enum! {
    pub enum Kind { Surfaces, Clusters }
}

pub struct PairKind;

impl Tool for PairKind {
    type Answer = Kind;
    fn ask(&self, _: &mut LinkCtx<'_>) -> Kind {
        Kind::Surfaces
    }
}

oracle! {
    crate = ::radiosity;
    oracle ByKind {
        start => kind;
        kind: PairKind { Surfaces => link, Clusters => subdivide_both, Mixed => stop }
    }
}

fn main() {}
