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
    SourceVariation(SourceVariation),
    PartialVisibility(PartialVisibility),
    ClusterError(ClusterError),
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

/// `$e` with `$t` bound to the tool inside whichever variant `$tool` is: the one list of variants
/// that the generic dispatches ([`DynTool::ask`], [`DynTool::needs`]) share.
macro_rules! on_tool {
    ($tool:expr, $t:ident => $e:expr) => {
        match $tool {
            DynTool::BfAbove($t) => $e,
            DynTool::SourceVariation($t) => $e,
            DynTool::PartialVisibility($t) => $e,
            DynTool::ClusterError($t) => $e,
            DynTool::IrradianceChange($t) => $e,
            DynTool::FfGradient($t) => $e,
            DynTool::RayVisibility($t) => $e,
            DynTool::ReferenceVisibility($t) => $e,
            DynTool::ShaftClassify($t) => $e,
            DynTool::ShaftFfError($t) => $e,
            DynTool::Facing($t) => $e,
            DynTool::ClusterTooNear($t) => $e,
            DynTool::CanSubdivide($t) => $e,
            DynTool::Larger($t) => $e,
            DynTool::SplitFirst($t) => $e,
            DynTool::PlanesIntersect($t) => $e,
            DynTool::ProjectedAreaBelow($t) => $e,
            DynTool::NormalCone($t) => $e,
            DynTool::PreciseVisibility($t) => $e,
            DynTool::PreciseFormFactor($t) => $e,
            DynTool::Mark($t) => $e,
        }
    };
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
            "SourceVariation" => DynTool::SourceVariation(SourceVariation(f(0))),
            "PartialVisibility" => DynTool::PartialVisibility(PartialVisibility(f(0))),
            "ClusterError" => DynTool::ClusterError(ClusterError(f(0))),
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
        on_tool!(self, t => ask(t, ctx))
    }

    /// The pipeline services the tool needs ([`Tool::NEEDS`]).
    #[must_use]
    pub fn needs(&self) -> crate::refine::Needs {
        on_tool!(self, t => needs(t))
    }

    /// Variant names of the tool `name`'s answer enum (for checking the catalogue).
    #[must_use]
    pub fn answer_names(name: &str) -> Option<&'static [&'static str]> {
        let names: &'static [&'static str] = match name {
            "BfAbove" | "Facing" | "ClusterTooNear" | "PlanesIntersect" | "ProjectedAreaBelow" => YesNo::NAMES,
            "IrradianceChange" => Irradiance::NAMES,
            "SourceVariation" | "PartialVisibility" | "ClusterError" => ErrorBound::NAMES,
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
