//! The built-in tools as one enum, built from a name and argument values, so the interpreter can
//! ask any of them. Each variant calls the same [`Tool`] implementation the macro's code calls.

use crate::oracle::tools::*;
use crate::oracle::{Answer, Tool};
use crate::refine::LinkCtx;

/// A built-in tool with its arguments bound.
#[derive(Clone, Copy, Debug)]
#[allow(missing_docs)]
pub enum DynTool {
    BfAbove(BfAbove),
    IrradianceChange(IrradianceChange),
    FfGradient(FfGradient),
    RayVisibility(RayVisibility),
    ReferenceVisibility(ReferenceVisibility),
    ShaftClassify(ShaftClassify),
    ShaftFfError(ShaftFfError),
    Facing(Facing),
    ClusterTooNear(ClusterTooNear),
    CanSubdivide(CanSubdivide),
    Larger(Larger),
    SplitFirst(SplitFirst),
    PlanesIntersect(PlanesIntersect),
    ProjectedAreaBelow(ProjectedAreaBelow),
    NormalCone(NormalCone),
    PreciseVisibility(PreciseVisibility),
    PreciseFormFactor(PreciseFormFactor),
    Mark(Mark),
}

fn needs<T: Tool>(_: &T) -> crate::refine::Needs {
    T::NEEDS
}

#[inline]
fn ask<T: Tool>(t: &T, ctx: &mut LinkCtx<'_>) -> (usize, &'static [&'static str]) {
    let a = t.ask(ctx);
    (a.index(), <T::Answer as Answer>::NAMES)
}

impl DynTool {
    /// The tool `name` with argument values `args` (counts are checked by validation; a missing
    /// argument reads 0). `None` for a name that is not a built-in tool.
    #[must_use]
    pub fn build(name: &str, args: &[f64]) -> Option<DynTool> {
        let f = |i: usize| args.get(i).copied().unwrap_or(0.0);
        let u = |i: usize| f(i) as u32;
        Some(match name {
            "BfAbove" => DynTool::BfAbove(BfAbove(f(0))),
            "IrradianceChange" => DynTool::IrradianceChange(IrradianceChange(f(0))),
            "FfGradient" => DynTool::FfGradient(FfGradient(f(0))),
            "RayVisibility" => DynTool::RayVisibility(RayVisibility(u(0))),
            "ReferenceVisibility" => DynTool::ReferenceVisibility(ReferenceVisibility),
            "ShaftClassify" => DynTool::ShaftClassify(ShaftClassify),
            "ShaftFfError" => DynTool::ShaftFfError(ShaftFfError(f(0))),
            "Facing" => DynTool::Facing(Facing),
            "ClusterTooNear" => DynTool::ClusterTooNear(ClusterTooNear),
            "CanSubdivide" => DynTool::CanSubdivide(CanSubdivide(f(0))),
            "Larger" => DynTool::Larger(Larger),
            "SplitFirst" => DynTool::SplitFirst(SplitFirst),
            "PlanesIntersect" => DynTool::PlanesIntersect(PlanesIntersect),
            "ProjectedAreaBelow" => DynTool::ProjectedAreaBelow(ProjectedAreaBelow(f(0))),
            "NormalCone" => DynTool::NormalCone(NormalCone),
            "PreciseVisibility" => DynTool::PreciseVisibility(PreciseVisibility(u(0))),
            "PreciseFormFactor" => DynTool::PreciseFormFactor(PreciseFormFactor),
            "Mark" => DynTool::Mark(Mark(u(0))),
            _ => return None,
        })
    }

    /// Asks the tool: the answer's index and the answer enum's variant names.
    #[inline]
    pub fn ask(&self, ctx: &mut LinkCtx<'_>) -> (usize, &'static [&'static str]) {
        match self {
            DynTool::BfAbove(t) => ask(t, ctx),
            DynTool::IrradianceChange(t) => ask(t, ctx),
            DynTool::FfGradient(t) => ask(t, ctx),
            DynTool::RayVisibility(t) => ask(t, ctx),
            DynTool::ReferenceVisibility(t) => ask(t, ctx),
            DynTool::ShaftClassify(t) => ask(t, ctx),
            DynTool::ShaftFfError(t) => ask(t, ctx),
            DynTool::Facing(t) => ask(t, ctx),
            DynTool::ClusterTooNear(t) => ask(t, ctx),
            DynTool::CanSubdivide(t) => ask(t, ctx),
            DynTool::Larger(t) => ask(t, ctx),
            DynTool::SplitFirst(t) => ask(t, ctx),
            DynTool::PlanesIntersect(t) => ask(t, ctx),
            DynTool::ProjectedAreaBelow(t) => ask(t, ctx),
            DynTool::NormalCone(t) => ask(t, ctx),
            DynTool::PreciseVisibility(t) => ask(t, ctx),
            DynTool::PreciseFormFactor(t) => ask(t, ctx),
            DynTool::Mark(t) => ask(t, ctx),
        }
    }

    /// The pipeline services the tool needs ([`Tool::NEEDS`]).
    #[must_use]
    pub fn needs(&self) -> crate::refine::Needs {
        match self {
            DynTool::BfAbove(t) => needs(t),
            DynTool::IrradianceChange(t) => needs(t),
            DynTool::FfGradient(t) => needs(t),
            DynTool::RayVisibility(t) => needs(t),
            DynTool::ReferenceVisibility(t) => needs(t),
            DynTool::ShaftClassify(t) => needs(t),
            DynTool::ShaftFfError(t) => needs(t),
            DynTool::Facing(t) => needs(t),
            DynTool::ClusterTooNear(t) => needs(t),
            DynTool::CanSubdivide(t) => needs(t),
            DynTool::Larger(t) => needs(t),
            DynTool::SplitFirst(t) => needs(t),
            DynTool::PlanesIntersect(t) => needs(t),
            DynTool::ProjectedAreaBelow(t) => needs(t),
            DynTool::NormalCone(t) => needs(t),
            DynTool::PreciseVisibility(t) => needs(t),
            DynTool::PreciseFormFactor(t) => needs(t),
            DynTool::Mark(t) => needs(t),
        }
    }

    /// Variant names of the tool `name`'s answer enum (for checking the catalogue).
    #[must_use]
    pub fn answer_names(name: &str) -> Option<&'static [&'static str]> {
        let names: &'static [&'static str] = match name {
            "BfAbove" | "Facing" | "ClusterTooNear" | "PlanesIntersect" | "ProjectedAreaBelow" => YesNo::NAMES,
            "IrradianceChange" => Irradiance::NAMES,
            "FfGradient" | "ShaftFfError" => FfSpread::NAMES,
            "RayVisibility" => VisibilityClass::NAMES,
            "ReferenceVisibility" => ReferenceClass::NAMES,
            "ShaftClassify" => ShaftAnswer::NAMES,
            "CanSubdivide" => Subdividable::NAMES,
            "Larger" | "SplitFirst" => Side::NAMES,
            "NormalCone" => Cone::NAMES,
            "PreciseVisibility" | "PreciseFormFactor" | "Mark" => Done::NAMES,
            _ => return None,
        };
        Some(names)
    }
}
