//! What the link criteria bound the error of, and how many segments a kept link's visibility is
//! sampled with.

/// What the link criteria bound the error of, at each receiver.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Criterion {
    /// The radiosity `B = E + ρ·H`: how a shadow falls within a receiver counts in proportion to
    /// its reflectance, so a black receiver's irradiance is never refined for a shadow.
    Radiosity,
    /// The irradiance `H`, whatever the receiver's reflectance: a black sensor's penumbra is
    /// refined like a white wall's (lux and absorbed power follow from `H`). The default.
    #[default]
    Irradiance,
}

impl Criterion {
    /// Every criterion, in the order the CLI lists them.
    pub const ALL: [Criterion; 2] = [Criterion::Radiosity, Criterion::Irradiance];

    /// The name the CLI and `stats.json` use.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Criterion::Radiosity => "radiosity",
            Criterion::Irradiance => "irradiance",
        }
    }

    /// The criterion named `name`.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Criterion> {
        Criterion::ALL.into_iter().find(|c| c.name() == name)
    }

    /// How many segments the visibility a new link keeps is sampled with, for `--rays` `rays`:
    /// `rays`, or [`KEPT_VISIBILITY_FACTOR`] times as many under the irradiance criterion
    /// ([`LinkCtx::fresh_visibility`](super::LinkCtx::fresh_visibility)), except for a link of reflected light that the oracle kept
    /// without drawing any ([`Services::reflected_rays`](super::Services::reflected_rays)). Each link records its count
    /// ([`crate::refine::Link::rays`]) for the error estimate's visibility noise.
    #[must_use]
    pub fn kept_rays(self, rays: u32) -> u32 {
        match self {
            Criterion::Radiosity => rays,
            Criterion::Irradiance => rays.saturating_mul(KEPT_VISIBILITY_FACTOR),
        }
    }
}

/// Under [`Criterion::Irradiance`], how many times `--rays` segments the visibility kept for a new
/// link is sampled with ([`LinkCtx::fresh_visibility`](super::LinkCtx::fresh_visibility); but see [`Services::reflected_rays`](super::Services::reflected_rays)).
/// CIE 171 case 5.7's black sensors at
/// `--eps 0.01`, seeds 1–3, worst error: a fresh sample of `--rays` segments 1.6–3.6%, of 4 times
/// as many 0.41–0.55% (17–23k links, 0.2 s); more rays for the oracle's own decision (up to 16
/// times, where the estimate's error was over half the threshold) doubled the links and changed
/// nothing.
pub const KEPT_VISIBILITY_FACTOR: u32 = 4;

/// The largest fraction of a link an occluder can hide (or a gap can open) while `n` segments
/// all miss it, about one time in twenty: `UNSEEN_FRACTION / n` (the rule of three).
pub const UNSEEN_FRACTION: f64 = 3.0;
