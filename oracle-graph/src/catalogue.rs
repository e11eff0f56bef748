//! The built-in tools: name, kind, answers (in the order of the tool's answer enum), arguments,
//! and the link data each one reads. The macro checks built-in nodes against this list with its
//! own messages; the DAG runtime accepts only these tools.

use crate::model::ParamType;

/// Whether a tool asks a question or does something.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToolKind {
    /// Reads the link and answers; no side effect beyond memoised link data.
    Question,
    /// Computes or records something (its only answer is `Done`).
    Command,
}

/// A term of the per-link data manager a tool may compute and store.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Slot {
    /// Form factor (estimate or precise, with its quality).
    FormFactor,
    /// Largest point form factor over the receiver.
    FormFactorMax,
    /// Smallest and largest point form factor over the receiver.
    FormFactorRange,
    /// Visibility fraction and its ray count.
    Visibility,
    /// The centre-to-centre axis and the projected areas along it.
    Axis,
    /// A mark left on the link.
    Mark,
    /// The shaft classification and candidate occluders.
    Shaft,
    /// How strongly the emitter's radiosity variation shows at the receiver.
    SourceVariationWeight,
}

impl Slot {
    /// Lowercase name, for listings.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Slot::FormFactor => "form_factor",
            Slot::FormFactorMax => "form_factor_max",
            Slot::FormFactorRange => "form_factor_range",
            Slot::Visibility => "visibility",
            Slot::Axis => "axis",
            Slot::Mark => "mark",
            Slot::Shaft => "shaft",
            Slot::SourceVariationWeight => "source_variation_weight",
        }
    }
}

/// One argument a tool takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArgSpec {
    /// Name, for messages.
    pub name: &'static str,
    /// Type.
    pub ty: ParamType,
}

/// A built-in tool.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToolInfo {
    /// Name as written in a graph (the Rust type name).
    pub name: &'static str,
    /// Question or command.
    pub kind: ToolKind,
    /// Answers in enum order; the answer index of the runtime is the position here.
    pub answers: &'static [&'static str],
    /// Arguments in order.
    pub args: &'static [ArgSpec],
    /// Link data the tool computes or reads.
    pub slots: &'static [Slot],
    /// One line saying what it answers.
    pub doc: &'static str,
}

impl ToolInfo {
    /// The position of `answer` in [`ToolInfo::answers`].
    #[must_use]
    pub fn answer_index(&self, answer: &str) -> Option<usize> {
        self.answers.iter().position(|a| *a == answer)
    }
}

const YES_NO: &[&str] = &["Yes", "No"];
const DONE: &[&str] = &["Done"];
const F64: ParamType = ParamType::F64;
const U32: ParamType = ParamType::U32;

/// Every built-in tool, sorted by category (energy, visibility, geometry, commands).
pub const BUILTIN_TOOLS: &[ToolInfo] = &[
    ToolInfo {
        name: "BfAbove",
        kind: ToolKind::Question,
        answers: YES_NO,
        args: &[ArgSpec { name: "eps", ty: F64 }],
        slots: &[Slot::FormFactorMax],
        doc: "is B_S · F_max above eps times the receiver's irradiance (the BF criterion, relative to the receiver)",
    },
    ToolInfo {
        name: "SourceVariation",
        kind: ToolKind::Question,
        answers: &["Above", "Below"],
        args: &[ArgSpec { name: "eps", ty: F64 }],
        slots: &[Slot::SourceVariationWeight],
        doc: "is F · (unevenness of the kernel over the source) · (variation of the source's radiosity) / 4 above eps times the receiver's irradiance",
    },
    ToolInfo {
        name: "PartialVisibility",
        kind: ToolKind::Question,
        answers: &["Above", "Below"],
        args: &[ArgSpec { name: "eps", ty: F64 }],
        slots: &[Slot::FormFactorMax, Slot::Visibility],
        doc: "is 2 V (1 - V) · rho_R · B_S · F_max (a partly visible link's error in the light the receiver reflects) above eps times the receiver's irradiance",
    },
    ToolInfo {
        name: "ClusterError",
        kind: ToolKind::Question,
        answers: &["Above", "Below"],
        args: &[ArgSpec { name: "eps", ty: F64 }],
        slots: &[Slot::FormFactor],
        doc: "is the cluster approximation's error, B_S · F · ((r_S + r_R) / d)², above eps times the receiver's irradiance",
    },
    ToolInfo {
        name: "IrradianceChange",
        kind: ToolKind::Question,
        answers: &["Significant", "Negligible"],
        args: &[ArgSpec { name: "threshold", ty: F64 }],
        slots: &[Slot::FormFactor],
        doc: "would the link change the receiver's irradiance by more than threshold times itself",
    },
    ToolInfo {
        name: "FfGradient",
        kind: ToolKind::Question,
        answers: &["Above", "Below"],
        args: &[ArgSpec { name: "threshold", ty: F64 }],
        slots: &[Slot::FormFactorRange],
        doc: "is the spread (max - min) of the point form factor over the receiver above threshold",
    },
    ToolInfo {
        name: "RayVisibility",
        kind: ToolKind::Question,
        answers: &["Visible", "Invisible", "Partial", "ProbablyVisible", "ProbablyInvisible", "ProbablyPartial", "TooComplex"],
        args: &[ArgSpec { name: "rays", ty: U32 }],
        slots: &[Slot::Visibility],
        doc: "classifies visibility with that many rays (probable answers when rays are few)",
    },
    ToolInfo {
        name: "ReferenceVisibility",
        kind: ToolKind::Question,
        answers: &["Visible", "Invisible", "Partial"],
        args: &[],
        slots: &[Slot::Visibility],
        doc: "exact-as-possible visibility class (many rays), the reference of visibility studies",
    },
    ToolInfo {
        name: "ShaftClassify",
        kind: ToolKind::Question,
        answers: &["Invisible", "Visible", "Partial"],
        args: &[],
        slots: &[Slot::Shaft],
        doc: "the link's shaft: one occluder blocks it whole, nothing enters it, or something may occlude (needs shafts)",
    },
    ToolInfo {
        name: "ShaftFfError",
        kind: ToolKind::Question,
        answers: &["Above", "Below"],
        args: &[ArgSpec { name: "eps", ty: F64 }],
        slots: &[Slot::FormFactorMax, Slot::FormFactorRange, Slot::Shaft],
        doc: "is B_S · (F_max - F_min) above eps times the receiver's irradiance, F_min = 0 unless the shaft is empty (needs shafts)",
    },
    ToolInfo {
        name: "Facing",
        kind: ToolKind::Question,
        answers: YES_NO,
        args: &[],
        slots: &[],
        doc: "can the two elements see each other's front (neither lies behind the other's plane)",
    },
    ToolInfo {
        name: "ClusterTooNear",
        kind: ToolKind::Question,
        answers: YES_NO,
        args: &[],
        slots: &[],
        doc: "is a cluster involved and the pair too close for the isotropic cluster approximation",
    },
    ToolInfo {
        name: "CanSubdivide",
        kind: ToolKind::Question,
        answers: &["Neither", "Emitter", "Receiver", "Both"],
        args: &[ArgSpec { name: "min_area", ty: F64 }],
        slots: &[],
        doc: "which elements can still be subdivided (surfaces: children of at least min_area)",
    },
    ToolInfo {
        name: "Larger",
        kind: ToolKind::Question,
        answers: &["Emitter", "Receiver"],
        args: &[],
        slots: &[],
        doc: "which element is larger by bounding radius (ties: the emitter)",
    },
    ToolInfo {
        name: "SplitFirst",
        kind: ToolKind::Question,
        answers: &["Emitter", "Receiver"],
        args: &[],
        slots: &[],
        doc: "which element to subdivide first: a cluster before a surface when apart, else the larger by bounding radius",
    },
    ToolInfo {
        name: "PlanesIntersect",
        kind: ToolKind::Question,
        answers: YES_NO,
        args: &[],
        slots: &[],
        doc: "does the emitter cross the receiver's support plane or the other way round",
    },
    ToolInfo {
        name: "ProjectedAreaBelow",
        kind: ToolKind::Question,
        answers: YES_NO,
        args: &[ArgSpec { name: "threshold", ty: F64 }],
        slots: &[Slot::Axis],
        doc: "are both areas projected along the centre-to-centre axis below threshold (scene units²)",
    },
    ToolInfo {
        name: "NormalCone",
        kind: ToolKind::Question,
        answers: &["Facing", "Away", "Mixed"],
        args: &[],
        slots: &[Slot::Axis],
        doc: "do both normals face along the centre-to-centre axis, both face away, or neither (clusters)",
    },
    ToolInfo {
        name: "PreciseVisibility",
        kind: ToolKind::Command,
        answers: DONE,
        args: &[ArgSpec { name: "rays", ty: U32 }],
        slots: &[Slot::Visibility],
        doc: "computes the visibility fraction with that many rays and stores it",
    },
    ToolInfo {
        name: "PreciseFormFactor",
        kind: ToolKind::Command,
        answers: DONE,
        args: &[],
        slots: &[Slot::FormFactor],
        doc: "computes the precise form factor and stores it",
    },
    ToolInfo {
        name: "Mark",
        kind: ToolKind::Command,
        answers: DONE,
        args: &[ArgSpec { name: "label", ty: U32 }],
        slots: &[Slot::Mark],
        doc: "leaves a numbered mark on the link (for studies and traces)",
    },
];

/// The built-in tool called `name`.
#[must_use]
pub fn builtin(name: &str) -> Option<&'static ToolInfo> {
    BUILTIN_TOOLS.iter().find(|t| t.name == name)
}

/// The link data slots the built-in tools of `graph` fill, sorted and without repeats: what the
/// data manager stores for this graph (a graph without visibility tools has no visibility slot).
#[must_use]
pub fn slots(graph: &crate::Graph) -> Vec<Slot> {
    let mut out: Vec<Slot> = graph.nodes.iter().filter_map(|n| builtin(&n.tool.name)).flat_map(|t| t.slots.iter().copied()).collect();
    out.sort();
    out.dedup();
    out
}
