//! A canopy written as a scene file: the leaves in an OBJ file, a ground, a `[sun]`, a `[sky]` and
//! a calculation grid below the canopy's centre.

use super::beer::{beam_transmittance, diffuse_transmittance, sky_transmittance};
use super::{Canopy, CanopyError, G_SPHERICAL};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// What [`write_scene_file`] puts around the leaves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneFileOptions {
    /// Ground reflectance.
    pub ground_reflectance: f64,
    /// The sun's zenith angle, degrees (below 90).
    pub sun_zenith: f64,
    /// The sun's azimuth, degrees clockwise from north (+y).
    pub sun_azimuth: f64,
    /// Direct normal irradiance, W/m² (0: no `[sun]`).
    pub direct_normal: f64,
    /// Diffuse horizontal irradiance of a uniform sky, W/m² (0: no `[sky]`).
    pub diffuse_horizontal: f64,
    /// Spacing of the calculation grid below the canopy's centre.
    pub grid_spacing: f64,
}

impl Default for SceneFileOptions {
    fn default() -> Self {
        SceneFileOptions {
            ground_reflectance: 0.0,
            sun_zenith: 30.0,
            sun_azimuth: 180.0,
            direct_normal: 800.0,
            diffuse_horizontal: 100.0,
            grid_spacing: 0.25,
        }
    }
}

/// Writes `canopy.toml` and `leaves.obj` into `dir` (created if missing): the leaves (black), a
/// ground, the sun and a uniform 145-cell sky as `options` says, and a calculation grid `below`
/// on the ground, inside [`Canopy::margin`] of the sun's zenith angle. The file's header states
/// the parameters and what theory expects. Returns the scene file's path.
pub fn write_scene_file(canopy: &Canopy, options: &SceneFileOptions, dir: &Path) -> Result<PathBuf, CanopyError> {
    let o = options;
    if !(0.0..90.0).contains(&o.sun_zenith) {
        return Err(CanopyError(format!("sun zenith {} must be in [0, 90) degrees", o.sun_zenith)));
    }
    if !o.sun_azimuth.is_finite() {
        return Err(CanopyError(format!("sun azimuth {} is not finite", o.sun_azimuth)));
    }
    for (what, v) in [("direct normal irradiance", o.direct_normal), ("diffuse horizontal irradiance", o.diffuse_horizontal)] {
        if !v.is_finite() || v < 0.0 {
            return Err(CanopyError(format!("{what} must be finite and non-negative, got {v}")));
        }
    }
    if !(o.ground_reflectance.is_finite() && (0.0..1.0).contains(&o.ground_reflectance)) {
        return Err(CanopyError(format!("ground reflectance {} must be in [0, 1)", o.ground_reflectance)));
    }
    if !o.grid_spacing.is_finite() || o.grid_spacing <= 0.0 {
        return Err(CanopyError(format!("grid spacing must be positive, got {}", o.grid_spacing)));
    }
    let p = &canopy.params;
    let zenith = o.sun_zenith.to_radians();
    let half = 0.5 * p.extent - canopy.margin(zenith);
    if half <= 0.0 {
        return Err(CanopyError(format!(
            "the canopy is too small for a sun {} degrees from the zenith: nothing below it is farther than {:.3} from its edge",
            o.sun_zenith,
            canopy.margin(zenith)
        )));
    }
    let lai = canopy.lai();
    let site = crate::daylight::Site::default();
    let toward = -site.direction(zenith, o.sun_azimuth.to_radians());
    let sky = crate::daylight::sky(crate::daylight::SkyModel::Uniform, [1.0; 3], 145, &site).map_err(|e| CanopyError(e.to_string()))?;
    let mut t = String::new();
    let _ = writeln!(
        t,
        "# A random canopy (radiosity generate canopy): {} black square leaves of side {}, normals uniform",
        canopy.leaves.len(),
        p.leaf_size
    );
    let _ = writeln!(
        t,
        "# over the sphere (G = {G_SPHERICAL}), centres uniform in x, y in [-{h}, {h}], z in [{}, {}]; seed {}.",
        p.base,
        p.base + p.height,
        p.seed,
        h = 0.5 * p.extent
    );
    let _ = writeln!(t, "# Leaf area index {lai:.6}. Theory, below the canopy farther than the margin from its edge:");
    let _ = writeln!(
        t,
        "#   sun at zenith {} deg: exp(-G*LAI/cos) = {:.6} of the direct light (grid `below` is inside the margin {:.4})",
        o.sun_zenith,
        beam_transmittance(lai, zenith),
        canopy.margin(zenith)
    );
    let _ = writeln!(
        t,
        "#   uniform sky: 2*E3(G*LAI) = {:.6} continuous, {:.6} for the 145-cell sky (the margin for its lowest cells is wider)",
        diffuse_transmittance(lai),
        sky_transmittance(&sky, lai)
    );
    let _ = writeln!(t, "name = \"canopy\"\nobj = \"leaves.obj\"\n");
    let _ = writeln!(t, "[[material]]\nname = \"leaf\"\nreflectance = 0.0\n");
    let _ = writeln!(t, "[[material]]\nname = \"ground\"\nreflectance = {}\n", o.ground_reflectance);
    let e = 0.5 * p.extent;
    let _ = writeln!(
        t,
        "[[polygon]]\nmaterial = \"ground\"\nvertices = [[{m}, {m}, 0.0], [{e}, {m}, 0.0], [{e}, {e}, 0.0], [{m}, {e}, 0.0]]\n",
        m = -e
    );
    if o.direct_normal > 0.0 {
        let _ =
            writeln!(t, "[sun]\ndirection = [{:.12}, {:.12}, {:.12}]\ndirect_normal = {}\n", toward.x, toward.y, toward.z, o.direct_normal);
    }
    if o.diffuse_horizontal > 0.0 {
        let _ = writeln!(t, "[sky]\nmodel = \"uniform\"\ndiffuse_horizontal = {}\ndirections = 145\n", o.diffuse_horizontal);
    }
    let _ = writeln!(
        t,
        "[[grid]]\nname = \"below\"\norigin = [{m}, {m}, 0.0]\nu = [{w}, 0.0, 0.0]\nv = [0.0, {w}, 0.0]\nspacing = {}\nnormal = [0.0, 0.0, 1.0]",
        o.grid_spacing,
        m = -half,
        w = 2.0 * half
    );
    let mut obj = String::with_capacity(canopy.leaves.len() * 170);
    let _ = writeln!(obj, "# {} leaves, z up\no leaves\nusemtl leaf", canopy.leaves.len());
    for q in &canopy.leaves {
        for v in q {
            let _ = writeln!(obj, "v {:.9} {:.9} {:.9}", v.x, v.y, v.z);
        }
    }
    for k in 0..canopy.leaves.len() {
        let i = 4 * k + 1;
        let _ = writeln!(obj, "f {} {} {} {}", i, i + 1, i + 2, i + 3);
    }
    std::fs::create_dir_all(dir).map_err(|e| CanopyError(format!("cannot create {}: {e}", dir.display())))?;
    let path = dir.join("canopy.toml");
    std::fs::write(&path, t).map_err(|e| CanopyError(format!("cannot write {}: {e}", path.display())))?;
    let obj_path = dir.join("leaves.obj");
    std::fs::write(&obj_path, obj).map_err(|e| CanopyError(format!("cannot write {}: {e}", obj_path.display())))?;
    Ok(path)
}
