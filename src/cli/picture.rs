//! The picture options of `radiosity solve`: the view (`--view`, Radiance's options or a `.vf`
//! file) and the false-colour image (`--false-colour`, `--scale`, `--false-colour-max`).

use radiosity::output::{FalseColourConfig, Quantity, Scale, ViewSpec};
use std::path::Path;

/// Picture options of `radiosity solve`.
#[derive(clap::Args, Debug)]
pub struct PictureArgs {
    /// The view, as Radiance gives it: options (`"-vp x y z -vd dx dy dz -vu ux uy uz -vh 60 -vv
    /// 45"`; perspective, `-vtv`, only) or a view file (`FILE.vf`, as `rvu` saves it). Options
    /// override the scene's camera, or the default view: a cut-away from above a corner (the backs
    /// of one-sided surfaces let the view through), or a view from inside when the scene's outside
    /// is dark. The image takes the view's aspect within --size. Plain scenes only.
    #[arg(long, value_name = "OPTIONS|FILE.vf", allow_hyphen_values = true)]
    pub view: Option<String>,
    /// What falsecolor.png (written beside image.png) shows: `irradiance` (the light falling on
    /// each surface), `radiosity` (the light leaving it), `daylight-factor` (the irradiance as a
    /// share of the sky's on an open horizontal plane, %: a scene lit by a sky alone), or `none`
    /// (no falsecolor.png). Plain scenes only.
    #[arg(long = "false-colour", value_enum, default_value_t = FalseColour::Irradiance)]
    pub false_colour: FalseColour,
    /// Scale of falsecolor.png: `linear` (from 0) or `log` (3 decades below the top).
    #[arg(long, value_enum, default_value_t = ColourScale::Linear)]
    pub scale: ColourScale,
    /// Top of falsecolor.png's scale, W/m² (default: the largest value of a non-emitting surface,
    /// rounded up to 1, 2, 2.5 or 5 times a power of ten).
    #[arg(long = "false-colour-max", value_name = "W/m2")]
    pub false_colour_max: Option<f64>,
}

/// Values of `--false-colour`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum FalseColour {
    /// Irradiance.
    Irradiance,
    /// Radiosity.
    Radiosity,
    /// The daylight factor (%).
    DaylightFactor,
    /// No falsecolor.png.
    None,
}

/// Values of `--scale`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColourScale {
    /// From 0 to the top.
    Linear,
    /// Logarithmic.
    Log,
}

impl PictureArgs {
    /// The view spec and false-colour settings these options give, checked (`instanced`: the scene
    /// is solved as instances, which take no view and write no falsecolor.png).
    pub fn settings(&self, instanced: bool) -> anyhow::Result<(Option<ViewSpec>, Option<FalseColourConfig>)> {
        anyhow::ensure!(
            self.view.is_none() || !instanced,
            "--view applies to plain scenes, not to instanced ones (nor to --instances auto)"
        );
        if let Some(max) = self.false_colour_max {
            anyhow::ensure!(max.is_finite() && max > 0.0, "--false-colour-max must be a positive number, got {max}");
        }
        let view = self.view.as_deref().map(parse_view).transpose()?;
        let quantity = match self.false_colour {
            FalseColour::Irradiance => Quantity::Irradiance,
            FalseColour::Radiosity => Quantity::Radiosity,
            FalseColour::DaylightFactor => Quantity::DaylightFactor,
            FalseColour::None => return Ok((view, None)),
        };
        let scale = match self.scale {
            ColourScale::Linear => Scale::Linear,
            ColourScale::Log => Scale::Log,
        };
        Ok((view, Some(FalseColourConfig { quantity, scale, max: self.false_colour_max, ..FalseColourConfig::default() })))
    }
}

/// `--view`: a view file when a file of that name exists or the value does not look like options
/// (it neither starts with `-` nor holds a space), otherwise inline options.
fn parse_view(value: &str) -> anyhow::Result<ViewSpec> {
    let path = Path::new(value);
    let inline = value.trim_start().starts_with('-') || value.contains(char::is_whitespace);
    if path.is_file() || !inline {
        return Ok(ViewSpec::read(path)?);
    }
    ViewSpec::parse(value).map_err(|e| anyhow::anyhow!("--view: {e}"))
}
