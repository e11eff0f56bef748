//! Command tools: they compute or record something and always answer `Done`.

use crate::formfactor::FormFactorQuality;
use crate::oracle::Tool;
use crate::refine::LinkCtx;

crate::answer_enum! {
    /// The only answer of a command.
    pub enum Done {
        /// The command ran.
        Done,
    }
}

/// Computes the visibility fraction with `rays` rays and stores it in the link data.
#[derive(Clone, Copy, Debug)]
pub struct PreciseVisibility(pub u32);

impl Tool for PreciseVisibility {
    type Answer = Done;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> Done {
        let _ = ctx.visibility(self.0);
        Done::Done
    }
}

/// Computes the precise form factor and stores it in the link data.
#[derive(Clone, Copy, Debug)]
pub struct PreciseFormFactor;

impl Tool for PreciseFormFactor {
    type Answer = Done;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> Done {
        let _ = ctx.form_factor(FormFactorQuality::Precise);
        Done::Done
    }
}

/// Leaves mark `label` on the link (for studies and traces).
#[derive(Clone, Copy, Debug)]
pub struct Mark(pub u32);

impl Tool for Mark {
    type Answer = Done;
    fn ask(&self, ctx: &mut LinkCtx<'_>) -> Done {
        ctx.data.mark = Some(self.0);
        Done::Done
    }
}
