//! Timing probe of single solves (development aid): `instancing_probe <scene.toml | tree:AGE> [eps] [nofg]`.
use radiosity_core::instancing::{self, FlattenOptions};
use radiosity_core::pipeline;
use radiosity_core::refine::BfHand;
use std::path::Path;

fn main() {
    let arg = std::env::args().nth(1).expect("scene");
    let s = match arg.strip_prefix("tree:") {
        Some(age) => instancing::generate_tree(age.parse().expect("age"), 1),
        None => {
            let text = std::fs::read_to_string(&arg).expect("read");
            instancing::parse(&text, Path::new(&arg), Path::new(".")).expect("parse")
        }
    };
    let flat = instancing::flatten(&s, &FlattenOptions::default()).expect("flatten");
    let t = std::time::Instant::now();
    let eps: f64 = std::env::args().nth(2).and_then(|e| e.parse().ok()).unwrap_or(0.01);
    let config = pipeline::Config { final_gather: std::env::args().nth(3).is_none(), ..pipeline::Config::default() };
    let solved = pipeline::run(&flat, &BfHand { params: radiosity_core::refine::BfParams { eps } }, &config, &|p| {
        eprintln!("{:.1}s {p:?}", t.elapsed().as_secs_f64())
    });
    println!(
        "{} polygons, {} elements, {} links, {:?} {:.2}s",
        flat.polygons.len(),
        solved.hierarchy.len(),
        solved.links.len(),
        solved.timings,
        t.elapsed().as_secs_f64()
    );
}
