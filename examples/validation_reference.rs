//! Regenerates the per-polygon reference radiosities of the validation rooms
//! (`radiosity-core/data/validation/*.csv`) with the dense reference solver
//! (`radiosity::validation::dense`): two uniform meshes, h and h/2, Richardson-extrapolated.
//!
//! `cargo run --release --example validation_reference [OUT_DIR]` (about a minute per room on two
//! cores; the finer Ward mesh needs 1.5 GB).

use radiosity::validation::{dense, scenes};
use std::io::Write;
use std::time::Instant;

fn main() -> std::io::Result<()> {
    let out = std::path::PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "radiosity-core/data/validation".into()));
    std::fs::create_dir_all(&out)?;
    // Ward's room: one material set, meshes 0.25 and 0.125 m.
    if std::env::args().nth(2).as_deref() != Some("--corner-only") {
        let ward = scenes::ward_room();
        write_reference(&out.join("ward_room.csv"), &ward, &[&ward], 0.25, "ward-room")?;
    }
    // The bright-corner room at three reflectances, meshes 0.25 and 0.125 m.
    let rooms: Vec<_> = [0.3, 0.7, 0.95].into_iter().map(scenes::corner_room).collect();
    let refs: Vec<&_> = rooms.iter().collect();
    write_reference(&out.join("corner_room.csv"), &rooms[0], &refs, 0.25, "corner-room")?;
    Ok(())
}

/// Solves `variants` (same geometry as `geometry`, other materials) on meshes `h` and `h/2` and
/// writes one row per (variant, polygon): `scene,polygon,group,b_h,b_h2,b_richardson` (grey scenes:
/// the first channel).
fn write_reference(
    path: &std::path::Path,
    geometry: &radiosity::scene::Scene,
    variants: &[&radiosity::scene::Scene],
    h: f64,
    what: &str,
) -> std::io::Result<()> {
    let mut rows = Vec::new();
    let mut systems = Vec::new();
    for size in [h, h / 2.0] {
        let t = Instant::now();
        let system = dense::DenseSystem::new(geometry, size);
        let sums = system.row_sums();
        let worst = sums.iter().map(|s| (s - 1.0).abs()).fold(0.0, f64::max);
        eprintln!(
            "{what}: h = {size}: {} patches, form factors in {:.1} s, worst row sum error {worst:.2e}",
            system.n_patches(),
            t.elapsed().as_secs_f64()
        );
        systems.push(system);
    }
    for scene in variants {
        let (rho, e) = dense::materials(scene);
        let coarse = systems[0].polygon_means(&rho, &e);
        let fine = systems[1].polygon_means(&rho, &e);
        let rich = dense::richardson(&coarse, &fine);
        for (i, p) in scene.polygons.iter().enumerate() {
            rows.push(format!(
                "{},{i},{},{:.10e},{:.10e},{:.10e}",
                scene.name, scene.groups[p.group as usize], coarse[i][0], fine[i][0], rich[i][0]
            ));
        }
    }
    let mut f = std::fs::File::create(path)?;
    writeln!(f, "# Per-polygon mean radiosity (W/m^2) of {what}, dense constant-element Galerkin (radiosity::validation::dense),")?;
    writeln!(
        f,
        "# uniform meshes h = {h} and {} m, Richardson-extrapolated (order 2). Regenerate: cargo run --release --example validation_reference",
        h / 2.0
    )?;
    writeln!(f, "scene,polygon,group,b_h,b_h2,b_richardson")?;
    for r in rows {
        writeln!(f, "{r}")?;
    }
    eprintln!("wrote {}", path.display());
    Ok(())
}
