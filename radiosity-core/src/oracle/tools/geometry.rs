//! Geometry questions: facing, cluster separation, subdividability, size, support planes,
//! projected area, normal cone.

use crate::hierarchy::Element;
use crate::oracle::Tool;
use crate::refine::LinkCtx;

crate::answer_enum! {
    /// A yes/no answer.
    pub enum YesNo {
        /// Yes.
        Yes,
        /// No.
        No,
    }
}

impl YesNo {
    /// `Yes` when `b`.
    #[must_use]
    #[inline]
    pub fn from_bool(b: bool) -> YesNo {
        if b { YesNo::Yes } else { YesNo::No }
    }
}

/// Can the two elements see each other's front? No when one lies entirely behind the other's
/// plane ([`LinkCtx::facing`]).
#[derive(Clone, Copy, Debug)]
pub struct Facing;

impl Tool for Facing {
    type Answer = YesNo;
    #[inline]
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> YesNo {
        YesNo::from_bool(ctx.facing())
    }
}

/// Is the pair too near for a link ([`LinkCtx::too_near`]): a cluster involved and the pair too
/// near for the isotropic approximation, or two surfaces crossing each other?
#[derive(Clone, Copy, Debug)]
pub struct ClusterTooNear;

impl Tool for ClusterTooNear {
    type Answer = YesNo;
    #[inline]
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> YesNo {
        YesNo::from_bool(ctx.too_near())
    }
}

crate::answer_enum! {
    /// Answer of [`CanSubdivide`].
    pub enum Subdividable {
        /// Neither element can be subdivided.
        Neither,
        /// Only the emitter.
        Emitter,
        /// Only the receiver.
        Receiver,
        /// Both.
        Both,
    }
}

/// Area of each child of a surface relative to its parent (regular subdivision into four).
pub const SURFACE_CHILD_FRACTION: f64 = 0.25;

/// Which elements can still be subdivided: the hierarchy allows it
/// ([`crate::hierarchy::Hierarchy::can_subdivide`]) and, for surfaces, the children would have at
/// least `min_area` (0: the hierarchy's own limit only).
#[derive(Clone, Copy, Debug)]
pub struct CanSubdivide(pub f64);

impl Tool for CanSubdivide {
    type Answer = Subdividable;
    #[inline]
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> Subdividable {
        let h = ctx.hierarchy();
        let can = |id: u32| {
            let e = h.get(id);
            h.can_subdivide(id) && (e.is_cluster() || e.area * SURFACE_CHILD_FRACTION >= self.0)
        };
        match (can(ctx.emitter), can(ctx.receiver)) {
            (false, false) => Subdividable::Neither,
            (true, false) => Subdividable::Emitter,
            (false, true) => Subdividable::Receiver,
            (true, true) => Subdividable::Both,
        }
    }
}

crate::answer_enum! {
    /// One end of a link.
    pub enum Side {
        /// The emitter.
        Emitter,
        /// The receiver.
        Receiver,
    }
}

/// Which element is larger by bounding radius (ties: the emitter).
#[derive(Clone, Copy, Debug)]
pub struct Larger;

impl Tool for Larger {
    type Answer = Side;
    #[inline]
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> Side {
        if ctx.emitter_element().radius >= ctx.receiver_element().radius { Side::Emitter } else { Side::Receiver }
    }
}

/// Which element to subdivide first: a cluster before a surface when they are apart, otherwise
/// the larger by bounding radius (ties: the emitter); see [`crate::refine::emitter_first`].
#[derive(Clone, Copy, Debug)]
pub struct SplitFirst;

impl Tool for SplitFirst {
    type Answer = Side;
    #[inline]
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> Side {
        if crate::refine::emitter_first(ctx.emitter_element(), ctx.receiver_element()) { Side::Emitter } else { Side::Receiver }
    }
}

/// Relative tolerance (times the plane element's radius) within which a vertex counts as on a plane.
pub const PLANE_REL_TOL: f64 = 1e-9;

/// Does the emitter cross the receiver's support plane, or the receiver the emitter's? (vertices
/// strictly on both sides; clusters have no plane and never cross.)
#[derive(Clone, Copy, Debug)]
pub struct PlanesIntersect;

fn crosses(plane: &Element, other: &Element) -> bool {
    let (Some(p), Some(q)) = (plane.poly(), other.poly()) else { return false };
    let origin = p.v[0];
    let tol = PLANE_REL_TOL * plane.radius;
    let (mut above, mut below) = (false, false);
    for v in q.vertices() {
        let d = plane.normal.dot(*v - origin);
        above |= d > tol;
        below |= d < -tol;
    }
    above && below
}

impl Tool for PlanesIntersect {
    type Answer = YesNo;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> YesNo {
        let (s, r) = (ctx.emitter_element(), ctx.receiver_element());
        YesNo::from_bool(crosses(r, s) || crosses(s, r))
    }
}

/// Are both areas, projected along the centre-to-centre axis, below `threshold` (scene units²)?
#[derive(Clone, Copy, Debug)]
pub struct ProjectedAreaBelow(pub f64);

impl Tool for ProjectedAreaBelow {
    type Answer = YesNo;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> YesNo {
        let a = ctx.axis();
        YesNo::from_bool(a.projected_emitter.max(a.projected_receiver) < self.0)
    }
}

crate::answer_enum! {
    /// Answer of [`NormalCone`].
    pub enum Cone {
        /// Both fronts face along the axis toward each other.
        Facing,
        /// Both fronts face away from each other.
        Away,
        /// Anything else (one of each, a cluster, coincident centres).
        Mixed,
    }
}

/// Normal-cone test along the centre-to-centre axis: the emitter's normal toward the receiver and
/// the receiver's toward the emitter.
#[derive(Clone, Copy, Debug)]
pub struct NormalCone;

impl Tool for NormalCone {
    type Answer = Cone;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> Cone {
        let a = ctx.axis();
        let (s, r) = (ctx.emitter_element(), ctx.receiver_element());
        if s.is_cluster() || r.is_cluster() || a.distance == 0.0 {
            return Cone::Mixed;
        }
        let (cs, cr) = (s.normal.dot(a.dir), -r.normal.dot(a.dir));
        if cs > 0.0 && cr > 0.0 {
            Cone::Facing
        } else if cs <= 0.0 && cr <= 0.0 {
            Cone::Away
        } else {
            Cone::Mixed
        }
    }
}
