//! `bench instancing`, as an example until the CLI wires it: full vs instanced solve of a generated
//! tree (or the 8-cube room), each in its own process so that peak RSS is per method.
//!
//! Usage:
//!   cargo run --release --example instancing_bench -- tree <age> <seed> [eps] [--max-closed N]
//!   cargo run --release --example instancing_bench -- cubes [eps]
//!   cargo run --release --example instancing_bench -- count <age> <seed>
//! Internal: `--child full|instanced <scene args...> <out.bin>` runs one method and prints a JSON row.

use radiosity_core::instancing::bench::{BenchRow, bench_full, bench_instanced, load_means, save_means};
use radiosity_core::instancing::solver::relative_error;
use radiosity_core::instancing::{self, InstancedConfig, InstancedScene, generate_tree};
use std::path::Path;
use std::process::Command;

fn cubes_scene() -> InstancedScene {
    let mut s = String::from(
        "[[material]]\nname = \"wall\"\nreflectance = 0.5\n[[material]]\nname = \"cube\"\nreflectance = [0.7, 0.5, 0.3]\n[[material]]\nname = \"light\"\nreflectance = 0.0\nemission = 10.0\n[[box]]\nmin = [0, 0, 0]\nmax = [4, 4, 4]\nmaterial = \"wall\"\ninward = true\n[[polygon]]\nmaterial = \"light\"\nvertices = [[1.5, 1.5, 3.99], [1.5, 2.5, 3.99], [2.5, 2.5, 3.99], [2.5, 1.5, 3.99]]\n[[prototype]]\nname = \"cube\"\n[[prototype.box]]\nmin = [0, 0, 0]\nmax = [0.4, 0.4, 0.4]\nmaterial = \"cube\"\n",
    );
    for k in 0..8 {
        let (x, y, z) = (0.8 + 2.0 * (k & 1) as f64, 0.8 + 2.0 * ((k >> 1) & 1) as f64, 0.6 + 1.6 * ((k >> 2) & 1) as f64);
        s.push_str(&format!("\n[[instance]]\nof = \"cube\"\ntranslate = [{x}, {y}, {z}]\nrotate = [0, 0, {}]\n", 10 * k));
    }
    instancing::parse(&s, Path::new("cubes.toml"), Path::new(".")).expect("valid scene")
}

fn scene_of(args: &[String]) -> (InstancedScene, f64) {
    match args[0].as_str() {
        "tree" => {
            let age: u32 = args[1].parse().expect("age");
            let seed: u64 = args[2].parse().expect("seed");
            let eps = args.get(3).and_then(|e| e.parse().ok()).unwrap_or(0.01);
            (generate_tree(age, seed), eps)
        }
        "cubes" => (cubes_scene(), args.get(1).and_then(|e| e.parse().ok()).unwrap_or(0.01)),
        other => panic!("unknown scene `{other}`"),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("count") {
        for age in [5u32, 10, 15, 20, 25, 30, 35] {
            let t = generate_tree(age, args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1));
            let n = t.flattened_counts(false)[t.root as usize];
            println!(
                "age {age}: {} prototypes, {n} polygons flattened ({} with two-sided pairs)",
                t.prototypes.len(),
                t.flattened_counts(true)[t.root as usize]
            );
        }
        return;
    }
    let max_closed = args.iter().position(|a| a == "--max-closed").and_then(|i| args.get(i + 1)).and_then(|s| s.parse().ok());
    let args: Vec<String> = {
        let mut v = args.clone();
        if let Some(i) = v.iter().position(|a| a == "--max-closed") {
            v.drain(i..(i + 2).min(v.len()));
        }
        v
    };
    if args.first().map(String::as_str) == Some("--child") {
        let method = &args[1];
        let out = Path::new(args.last().expect("output path"));
        let (scene, eps) = scene_of(&args[2..args.len() - 1]);
        let mut config = InstancedConfig::default();
        config.bf.eps = eps;
        if let Some(n) = max_closed {
            config.max_closed_polygons = n;
        }
        config.cache_dir = Some(std::env::temp_dir().join("radiosity-instancing-cache"));
        config.trace = std::env::var_os("INSTANCING_TRACE").is_some();
        config.pipeline.final_gather = std::env::var_os("INSTANCING_NO_FINAL_GATHER").is_none();
        if let Some(r) = std::env::var("INSTANCING_VIS_RAYS").ok().and_then(|r| r.parse().ok()) {
            config.pipeline.visibility.rays = r;
        }
        let (row, means) = if method == "full" {
            let (row, means) = bench_full(&scene, &config).expect("full solve");
            (row, Some(means))
        } else {
            bench_instanced(&scene, &config, true).expect("instanced solve")
        };
        if let Some(m) = means {
            save_means(out, &m).expect("save");
        }
        println!("{}", serde_json::to_string(&row).expect("json"));
        return;
    }
    let exe = std::env::current_exe().expect("own path");
    let dir = std::env::temp_dir();
    let mut rows: Vec<BenchRow> = Vec::new();
    for method in ["instanced", "full"] {
        let out = dir.join(format!("instancing-bench-{method}-{}.bin", std::process::id()));
        let mut cmd = Command::new(&exe);
        cmd.arg("--child").arg(method).args(&args).arg(&out);
        if let Some(n) = max_closed {
            cmd.arg("--max-closed").arg(n.to_string());
        }
        let o = cmd.output().expect("child runs");
        let text = String::from_utf8_lossy(&o.stdout);
        let row: BenchRow = serde_json::from_str(text.lines().last().unwrap_or(""))
            .unwrap_or_else(|_| panic!("child failed: {}", String::from_utf8_lossy(&o.stderr)));
        eprintln!("{method}: {text}");
        rows.push(row);
    }
    let a = load_means(&dir.join(format!("instancing-bench-instanced-{}.bin", std::process::id()))).expect("instanced means");
    let f = load_means(&dir.join(format!("instancing-bench-full-{}.bin", std::process::id()))).expect("full means");
    let (worst, mean) = relative_error(&f, &a);
    println!("method,eps,polygons,seconds,peak_rss_mb,links,local_solves");
    for r in &rows {
        println!(
            "{},{},{},{:.3},{:.1},{},{}",
            r.method,
            r.eps,
            r.polygons,
            r.seconds,
            r.peak_rss_bytes as f64 / 1048576.0,
            r.links,
            r.local_solves
        );
    }
    println!("error of instanced vs full, % of max radiosity: max {:.3}, area-weighted mean {:.3}", 100.0 * worst, 100.0 * mean);
    println!(
        "speed-up {:.2}x, memory ratio {:.2}x",
        rows[1].seconds / rows[0].seconds.max(1e-9),
        rows[1].peak_rss_bytes as f64 / rows[0].peak_rss_bytes.max(1) as f64
    );
}
