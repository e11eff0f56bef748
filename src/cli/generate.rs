//! `radiosity generate {tree,forest}`: procedural poplar-like plants written as an instanced scene
//! (TOML plus one OBJ per prototype).

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
    },
}

/// Runs a generator and prints where the scene was written.
pub fn run(cmd: GenerateCommand) -> anyhow::Result<()> {
    let (scene, out, stem) = match cmd {
        GenerateCommand::Tree { age, seed, out } => {
            anyhow::ensure!((1..=200).contains(&age), "--age must be between 1 and 200, got {age}");
            (instancing::generate_tree(age, seed), out, "tree")
        }
        GenerateCommand::Forest { trees, min_age, max_age, seed, out } => {
            anyhow::ensure!(trees >= 1, "--trees must be at least 1");
            anyhow::ensure!(min_age >= 1 && min_age <= max_age, "need 1 <= --min-age <= --max-age");
            let params = ForestParams { trees, min_age, max_age, seed, ..ForestParams::default() };
            (instancing::generate_forest(&params), out, "forest")
        }
    };
    let path = instancing::write_scene(&scene, &out, stem)?;
    let counts = scene.flattened_counts(true);
    let flat = counts.get(scene.root as usize).copied().unwrap_or(0);
    println!("wrote {} ({} prototypes, {flat} polygons flattened, two-sided leaves counted twice)", path.display(), scene.prototypes.len());
    Ok(())
}
