//! `radiosity generate {tree,forest,canopy}`: procedural poplar-like plants written as an instanced
//! scene (TOML plus one OBJ per prototype), and random canopies of black leaves for validation
//! against Beer's law (see `radiosity::canopy`).

use radiosity::canopy::{self, CanopyParams, SceneFileOptions};
use radiosity::instancing::{self, ForestParams};
use std::path::PathBuf;

/// What to generate.
#[derive(clap::Subcommand, Debug)]
pub enum GenerateCommand {
    /// One tree: axes of the same kind and age are instances of one prototype.
    Tree {
        /// Age in years (a 30-year tree has about 107,000 polygons flattened).
        #[arg(long, default_value_t = 10)]
        age: u32,
        /// Seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output directory.
        #[arg(long, short, default_value = "tree")]
        out: PathBuf,
        #[command(flatten)]
        daylight: DaylightArgs,
    },
    /// A forest of trees of several ages on a square grid.
    Forest {
        /// Number of trees.
        #[arg(long, default_value_t = 64)]
        trees: u32,
        /// Youngest tree, years.
        #[arg(long, default_value_t = 10)]
        min_age: u32,
        /// Oldest tree, years.
        #[arg(long, default_value_t = 20)]
        max_age: u32,
        /// Seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output directory.
        #[arg(long, short, default_value = "forest")]
        out: PathBuf,
        #[command(flatten)]
        daylight: DaylightArgs,
    },
    /// A random canopy: black square leaves with normals uniform over the sphere, placed at random
    /// in a horizontal slab over a ground, lit by a sun and a uniform sky, with a calculation grid
    /// `below` on the ground where Beer's law applies (the file's header says what it predicts).
    Canopy {
        /// Leaf area index (one-sided leaf area per ground area).
        #[arg(long, default_value_t = 1.0)]
        lai: f64,
        /// Side of the square leaves.
        #[arg(long, default_value_t = 0.1)]
        leaf_size: f64,
        /// Side of the square the leaf centres are spread over (centred on the origin).
        #[arg(long, default_value_t = 10.0)]
        extent: f64,
        /// Thickness of the slab of leaf centres.
        #[arg(long, default_value_t = 2.0)]
        height: f64,
        /// Height of the lowest leaf centres above the ground (at least the leaf's half-diagonal).
        #[arg(long, default_value_t = 0.5)]
        base: f64,
        /// Seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// The sun's zenith angle, degrees.
        #[arg(long, default_value_t = 30.0)]
        sun_zenith: f64,
        /// The sun's azimuth, degrees clockwise from north (+y).
        #[arg(long, default_value_t = 180.0)]
        sun_azimuth: f64,
        /// Direct normal irradiance, W/m² (0: no sun).
        #[arg(long, default_value_t = 800.0)]
        direct_normal: f64,
        /// Diffuse horizontal irradiance of a uniform 145-cell sky, W/m² (0: no sky).
        #[arg(long, default_value_t = 100.0)]
        diffuse_horizontal: f64,
        /// Ground reflectance.
        #[arg(long, default_value_t = 0.0)]
        ground_reflectance: f64,
        /// Spacing of the calculation grid `below`.
        #[arg(long, default_value_t = 0.25)]
        grid_spacing: f64,
        /// Output directory (canopy.toml and leaves.obj).
        #[arg(long, short, default_value = "canopy")]
        out: PathBuf,
    },
}

/// Sun and sky instead of the three lamps, in bands PAR and NIR.
#[derive(clap::Args, Debug, Clone)]
pub struct DaylightArgs {
    /// Light the scene with the sun and the sky of a place and time instead of lamps, in two
    /// bands, PAR (400-700 nm) and NIR (700-2500 nm), with typical leaf, bark and soil optical
    /// properties per band.
    #[arg(long)]
    daylight: bool,
    /// Latitude of the place, degrees north.
    #[arg(long, default_value_t = 43.61, requires = "daylight", allow_negative_numbers = true)]
    latitude: f64,
    /// Longitude of the place, degrees east.
    #[arg(long, default_value_t = 3.88, requires = "daylight", allow_negative_numbers = true)]
    longitude: f64,
    /// Date and time, RFC 3339 with its UTC offset.
    #[arg(long, default_value = "2026-06-21T12:00:00+02:00", requires = "daylight")]
    time: String,
    /// Direct normal irradiance, PAR,NIR (W/m²).
    #[arg(long, default_value = "400,380", requires = "daylight")]
    direct_normal: String,
    /// Diffuse horizontal irradiance, PAR,NIR (W/m²).
    #[arg(long, default_value = "100,90", requires = "daylight")]
    diffuse_horizontal: String,
    /// Sky radiance model: uniform or cie-overcast.
    #[arg(long, default_value = "cie-overcast", requires = "daylight")]
    sky: String,
    /// Sky cells (46 or 145 like the turtle skies, or any count).
    #[arg(long, default_value_t = 145, requires = "daylight")]
    sky_directions: u32,
    /// Largest side of the ground's tiles (m): the instanced solve lights each top-level polygon
    /// by its mean, so the ground is split for the trees' shadows to show on it.
    #[arg(long, default_value_t = 0.5, requires = "daylight")]
    ground_tile: f64,
}

/// Optical properties per band (PAR, NIR) of the generated materials: reflectance, transmittance.
/// Typical green leaves absorb most PAR and scatter most NIR; bark and soil are darker in PAR.
const BAND_MATERIALS: &str = r#"bands = ["PAR", "NIR"]

[[material]]
name = "bark"
reflectance = [0.15, 0.35]

[[material]]
name = "leaf"
reflectance = [0.10, 0.45]
transmittance = [0.05, 0.40]
two_sided = true

[[material]]
name = "ground"
reflectance = [0.10, 0.25]

[[material]]
name = "light"
reflectance = 0.0
"#;

impl DaylightArgs {
    /// Two numbers `a,b`.
    fn pair(what: &str, text: &str) -> anyhow::Result<[f64; 2]> {
        let v: Vec<f64> = text
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| anyhow::anyhow!("--{what} `{text}`: give two numbers, PAR,NIR"))?;
        anyhow::ensure!(
            v.len() == 2 && v.iter().all(|x| x.is_finite() && *x >= 0.0),
            "--{what} `{text}`: give two non-negative numbers, PAR,NIR"
        );
        Ok([v[0], v[1]])
    }

    /// Rewrites the written scene file: band materials, the sun and the sky instead of lamps.
    fn apply(&self, path: &std::path::Path) -> anyhow::Result<()> {
        let dni = Self::pair("direct-normal", &self.direct_normal)?;
        let dhi = Self::pair("diffuse-horizontal", &self.diffuse_horizontal)?;
        anyhow::ensure!(self.sky == "uniform" || self.sky == "cie-overcast", "--sky `{}`: uniform or cie-overcast", self.sky);
        let text = std::fs::read_to_string(path)?;
        let (start, end) = match (text.find("[[material]]"), text.find("[[prototype]]")) {
            (Some(a), Some(b)) if a < b => (a, b),
            _ => anyhow::bail!("{}: unexpected layout of a generated scene", path.display()),
        };
        let daylight = format!(
            "[sun]\nlatitude = {}\nlongitude = {}\ntime = \"{}\"\ndirect_normal = [{:?}, {:?}]\n\n[sky]\nmodel = \"{}\"\ndiffuse_horizontal = [{:?}, {:?}]\ndirections = {}\n\n",
            self.latitude, self.longitude, self.time, dni[0], dni[1], self.sky, dhi[0], dhi[1], self.sky_directions
        );
        let head = &text[..start];
        let (first, rest) = head.split_at(head.find('\n').map_or(0, |i| i + 1));
        let out = format!("{first}{rest}{BAND_MATERIALS}\n{daylight}{}", &text[end..]);
        std::fs::write(path, out)?;
        // Checks the result (sun position, sky cells) before saying it was written.
        radiosity::instancing::load_with_lighting(path)?;
        Ok(())
    }
}

/// Runs a generator and prints where the scene was written.
pub fn run(cmd: GenerateCommand) -> anyhow::Result<()> {
    let (mut scene, out, stem, daylight) = match cmd {
        GenerateCommand::Canopy {
            lai,
            leaf_size,
            extent,
            height,
            base,
            seed,
            sun_zenith,
            sun_azimuth,
            direct_normal,
            diffuse_horizontal,
            ground_reflectance,
            grid_spacing,
            out,
        } => {
            let params = CanopyParams { lai, leaf_size, extent, base, height, seed };
            let c = canopy::random_leaves(&params)?;
            let options = SceneFileOptions { ground_reflectance, sun_zenith, sun_azimuth, direct_normal, diffuse_horizontal, grid_spacing };
            let path = canopy::write_scene_file(&c, &options, &out)?;
            println!(
                "wrote {} ({} leaves, LAI {:.4}; Beer's law below the canopy: {:.4} of the sun at {sun_zenith} degrees, {:.4} of a uniform sky)",
                path.display(),
                c.leaves.len(),
                c.lai(),
                canopy::beam_transmittance(c.lai(), sun_zenith.to_radians()),
                canopy::diffuse_transmittance(c.lai())
            );
            return Ok(());
        }
        GenerateCommand::Tree { age, seed, out, daylight } => {
            anyhow::ensure!((1..=200).contains(&age), "--age must be between 1 and 200, got {age}");
            (instancing::generate_tree(age, seed), out, "tree", daylight)
        }
        GenerateCommand::Forest { trees, min_age, max_age, seed, out, daylight } => {
            anyhow::ensure!(trees >= 1, "--trees must be at least 1");
            anyhow::ensure!(min_age >= 1 && min_age <= max_age, "need 1 <= --min-age <= --max-age");
            let params = ForestParams { trees, min_age, max_age, seed, ..ForestParams::default() };
            (instancing::generate_forest(&params), out, "forest", daylight)
        }
    };
    if daylight.daylight {
        // The lamps go: the sun and the sky light the scene.
        let light = scene.materials.iter().position(|m| m.name == instancing::plant::LIGHT).map(|i| i as u32);
        for p in &mut scene.prototypes {
            p.polygons.retain(|q| Some(q.material) != light);
        }
        // The ground in tiles: the instanced solve lights a top-level polygon by its mean.
        anyhow::ensure!(
            daylight.ground_tile > 0.0 && daylight.ground_tile.is_finite(),
            "--ground-tile must be a positive length, got {}",
            daylight.ground_tile
        );
        if let Some(g) = scene.materials.iter().position(|m| m.name == instancing::plant::GROUND) {
            let root = scene.root;
            instancing::plant::tile_quads(&mut scene, root, g as u32, daylight.ground_tile);
        }
    }
    let path = instancing::write_scene(&scene, &out, stem)?;
    if daylight.daylight {
        daylight.apply(&path)?;
    }
    let counts = scene.flattened_counts(true);
    let flat = counts.get(scene.root as usize).copied().unwrap_or(0);
    println!("wrote {} ({} prototypes, {flat} polygons flattened, two-sided leaves counted twice)", path.display(), scene.prototypes.len());
    Ok(())
}
