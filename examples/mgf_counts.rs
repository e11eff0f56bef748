//! Loads the RenderPark MGF scenes listed in `SOURCE.md` and compares our polygon and emitter counts
//! with RenderPark's patch and light counts from its table.
//!
//! Run: `cargo run --release --example mgf_counts -- /work/shared/scenes/renderpark_mgf [-v]`
//! (`-v` prints every warning message kept by the loader).

use radiosity::scene::mgf::{self, MgfOptions};
use radiosity::scene::{self, LoadOptions, Scene};
use std::path::PathBuf;
use std::time::Instant;

/// One row of SOURCE.md's table: file and RenderPark's (patches, lights).
struct Row {
    file: String,
    patches: Option<u64>,
    lights: Option<u64>,
    note: String,
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let verbose = args.iter().any(|a| a == "-v");
    let dir = PathBuf::from(args.iter().find(|a| *a != "-v").map_or("/work/shared/scenes/renderpark_mgf", String::as_str));
    let table = match std::fs::read_to_string(dir.join("SOURCE.md")) {
        Ok(text) => parse_table(&text),
        Err(e) => {
            eprintln!("{}: {e}", dir.join("SOURCE.md").display());
            std::process::exit(2);
        }
    };
    println!(
        "| file | ours | RenderPark | diff | emitting ours | lights RP | tris | quads | load ms | degenerate | triangulated | clamped mats | messages |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut failed = false;
    for row in &table {
        let path = dir.join(&row.file);
        let t = Instant::now();
        match scene::load(&path, &LoadOptions { allow_dark: true }) {
            Ok(s) => {
                let ms = t.elapsed().as_secs_f64() * 1e3;
                let n = s.polygons.len() as u64;
                let tris = s.polygons.iter().filter(|p| p.poly.n_vertices() == 3).count();
                let w = &s.warnings;
                println!(
                    "| {} | {n} | {} | {} | {} | {} | {tris} | {} | {ms:.0} | {} | {} | {} | {} |",
                    row.file,
                    opt(row.patches),
                    row.patches.map_or("-".into(), |p| format!("{:+}", n as i64 - p as i64)),
                    n_emitting(&s),
                    opt(row.lights),
                    s.polygons.len() - tris,
                    w.degenerate_faces,
                    w.triangulated_faces,
                    w.clamped_materials,
                    w.messages.len(),
                );
                if verbose {
                    for m in &w.messages {
                        println!("    {m}");
                    }
                }
            }
            Err(e) => {
                failed = true;
                // `{:#}` prints the chain of causes (an unreadable file's reason is its source).
                println!("| {} | ERROR: {:#} |", row.file, anyhow::Error::from(e));
            }
        }
    }
    println!();
    println!("Notes from SOURCE.md:");
    for row in table.iter().filter(|r| !r.note.is_empty()) {
        println!("- {}: {}", row.file, row.note);
    }
    println!();
    println!("RenderPark variants (two-sided materials get a twin patch when one-sidedness is not forced):");
    println!("| file | options | polygons | + twins | emitting (+ twins) |");
    println!("|---|---|---:|---:|---:|");
    for (file, nq) in [("corridor.mgf", 18), ("office1/graz.mgf", 4)] {
        let options = MgfOptions { quarter_circle_divisions: nq, force_one_sided: false };
        match mgf::load_with(&dir.join(file), &options) {
            Ok(s) => {
                let two_sided = |i: &usize| s.material_of(*i).two_sided;
                let twins = (0..s.polygons.len()).filter(two_sided).count();
                let emit_twins = (0..s.polygons.len()).filter(|i| two_sided(i) && s.material_of(*i).is_emitter()).count();
                let n = s.polygons.len();
                let e = n_emitting(&s);
                println!("| {file} | -nqcdivs {nq} -dont-force-onesided | {n} | {} | {} |", n + twins, e + emit_twins);
            }
            Err(e) => {
                failed = true;
                println!("| {file} | ERROR: {:#} |", anyhow::Error::from(e));
            }
        }
    }
    if failed {
        std::process::exit(1);
    }
}

fn n_emitting(s: &Scene) -> usize {
    (0..s.polygons.len()).filter(|&i| s.material_of(i).is_emitter()).count()
}

fn opt(v: Option<u64>) -> String {
    v.map_or("-".into(), |v| v.to_string())
}

/// Rows of the markdown table whose first cell names an `.mgf` file; the last cell reads
/// `patches (lights) [note]`, numbers with spaces as thousands separators.
fn parse_table(text: &str) -> Vec<Row> {
    let mut rows = Vec::new();
    for line in text.lines().filter(|l| l.starts_with('|')) {
        let cells: Vec<&str> = line.trim_matches('|').split('|').map(str::trim).collect();
        let (Some(first), Some(last)) = (cells.first(), cells.last()) else { continue };
        let Some(file) = first.split_whitespace().next().filter(|f| f.ends_with(".mgf")) else { continue };
        let (count, rest) = last.split_once('(').unwrap_or((last, ""));
        let digits: String = count.chars().filter(char::is_ascii_digit).collect();
        let (lights, note) = rest.split_once(')').unwrap_or(("", rest));
        rows.push(Row {
            file: file.to_owned(),
            patches: digits.parse().ok(),
            lights: lights.trim().parse().ok(),
            note: note.trim_start_matches([';', ' ']).trim().to_owned(),
        });
    }
    rows
}
