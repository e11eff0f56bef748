//! The shaft oracle (declared with `oracle!`, shaft culling on) against BF with plain rays: on the
//! stairs-and-beam scene (the published failure: steps lit from above went dark) and the duplex,
//! every polygon's radiosity agrees with the rays solution, and no directly lit tread is dark.

use radiosity::oracle::shaft::{ShaftOracle, ShaftOracleParams};
use radiosity::output::polygon_results;
use radiosity::pipeline::{self, Config, VisibilityMethod};
use radiosity::refine::{BfHand, BfParams};
use radiosity::scene::Scene;
use radiosity::scene::generated::{duplex, stairs_with_beam};
use radiosity::visibility::shaft::BoundingVolume;

/// Largest per-polygon difference allowed, relative to the largest non-emitting radiosity: the two
/// oracles refine differently, so the meshes differ; a wrongly dark step would differ by ~100% (measured: 2.1% stairs, 2.0% duplex).
const AGREEMENT_TOL: f64 = 0.05;

fn compare(scene: &Scene) -> f64 {
    let eps = 0.01;
    let rays = pipeline::run(scene, &BfHand { params: BfParams { eps } }, &Config::default(), &|_| {});
    let config = Config { visibility_method: VisibilityMethod::Shafts(BoundingVolume::Obb), ..Config::default() };
    let shaft = pipeline::run(scene, &ShaftOracle::new(ShaftOracleParams { eps, ..ShaftOracleParams::default() }), &config, &|_| {});
    assert!(shaft.shaft_classified[0] + shaft.shaft_classified[1] > 0, "the shafts classified some links without rays");
    let (a, b) = (polygon_results(&rays.hierarchy, &rays.solution), polygon_results(&shaft.hierarchy, &shaft.solution));
    let lit = |i: usize| !scene.materials[scene.polygons[i].material as usize].is_emitter();
    let max = (0..a.len()).filter(|&i| lit(i)).flat_map(|i| a[i].b).fold(0.0f64, f64::max);
    let worst = (0..a.len())
        .filter(|&i| lit(i))
        .flat_map(|i| (0..3).map(move |c| (i, c)))
        .map(|(i, c)| (a[i].b[c] - b[i].b[c]).abs())
        .fold(0.0f64, f64::max)
        / max;
    println!(
        "{}: rays {} links, shaft oracle {} links ({} invisible, {} visible without rays), worst difference {:.2}% of max",
        scene.name,
        rays.links.len(),
        shaft.links.len(),
        shaft.shaft_classified[0],
        shaft.shaft_classified[1],
        100.0 * worst
    );
    worst
}

#[test]
fn stairs_lit_from_above_stay_lit() {
    let worst = compare(&stairs_with_beam());
    assert!(worst < AGREEMENT_TOL, "worst polygon differs by {:.1}% of max", 100.0 * worst);
}

#[test]
fn duplex_agrees_with_plain_rays() {
    let worst = compare(&duplex());
    assert!(worst < AGREEMENT_TOL, "worst polygon differs by {:.1}% of max", 100.0 * worst);
}

/// The shaft oracle's tools declare that they need shafts, so a library solve with the default
/// configuration (plain rays requested) classifies shafts without being told.
#[test]
fn the_shaft_oracle_gets_shafts_from_a_default_pipeline() {
    use radiosity::oracle::registry;
    use radiosity::pipeline::{self, Config, VisibilityMethod};
    let shaft = registry::oracle("shaft", &[]).unwrap();
    let bf = registry::oracle("bf", &[]).unwrap();
    assert!(shaft.needs().shafts);
    assert!(!bf.needs().shafts);
    assert_ne!(pipeline::effective_visibility(shaft.as_ref(), VisibilityMethod::Rays), VisibilityMethod::Rays);
    let scene = radiosity::scene::generated::stairs_with_beam();
    let solved = pipeline::run(&scene, shaft.as_ref(), &Config::default(), &|_| {});
    assert!(solved.shaft_classified.iter().sum::<u64>() > 0, "no shaft was classified");
}

/// The shaft oracle's graph run by the DAG runtime (its shaft tools are built-ins) needs shafts
/// as the macro's release does and makes the same links and the same solution.
#[test]
fn the_dag_runtime_runs_the_shaft_oracle_as_the_macro_does() {
    use radiosity::oracle::runtime::DagOracle;
    use radiosity::refine::Oracle;
    let scene = duplex();
    let release = ShaftOracle::new(ShaftOracleParams::default());
    let dag = DagOracle::new(ShaftOracle::<radiosity::oracle::NoProbe>::GRAPH, &[]).expect("built-in tools only");
    assert!(dag.needs().shafts, "the interpreted graph needs shafts");
    let (a, b) = (pipeline::run(&scene, &release, &Config::default(), &|_| {}), pipeline::run(&scene, &dag, &Config::default(), &|_| {}));
    assert!(a.shaft_classified.iter().sum::<u64>() > 0);
    assert_eq!(a.shaft_classified, b.shaft_classified);
    assert_eq!(a.links.len(), b.links.len());
    let (pa, pb) = (polygon_results(&a.hierarchy, &a.solution), polygon_results(&b.hierarchy, &b.solution));
    assert!(pa.iter().zip(&pb).all(|(x, y)| x.b == y.b), "same decisions give the same solution");
}

/// `oracle explain shaft` shows the shaft's class and candidate count in the track. On the Cornell
/// box some polygon pair reaches the shaft node (its transfer is above the threshold) and has a
/// partly occluded shaft (the boxes stand between the light, the walls and the floor).
#[test]
fn the_explained_track_shows_the_shaft() {
    use radiosity::oracle::runtime::format_trace;
    let scene = radiosity::scene::cornell_box();
    let n = scene.polygons.len() as u32;
    let config = Config { levels: 1, ..Config::default() };
    let mut found = None;
    'search: for e in 0..n {
        for r in 0..n {
            if e == r {
                continue;
            }
            let (graph, trace) = radiosity::lab::explain("shaft", &[], &scene, &config, e, r).expect("built-in oracle");
            if let Some(step) = trace.iter().find(|s| graph.nodes[s.node].tool.name == "ShaftClassify") {
                let text = format_trace(&graph, &trace);
                if text.contains("shaft=partial (") {
                    assert!(step.shaft.is_some(), "{text}");
                    found = Some((e, r, text));
                    break 'search;
                }
            }
        }
    }
    let (e, r, text) = found.expect("some pair's shaft is partly occluded");
    assert!(text.contains("ShaftClassify -> Partial"), "{e} -> {r}: {text}");
}

/// The shaft oracle's graph as a graph file: BF's graph file with the shaft classification after
/// the transfer test, a fully visible shaft skipping the visibility test. The runtime gives it
/// shafts and the release's links.
#[test]
fn a_graph_file_with_shaft_tools_gets_shafts() {
    use radiosity::oracle::bf::BF_TOML;
    use radiosity::oracle::runtime::{DagOracle, parse_graph};
    use radiosity::refine::Oracle;
    const SHAFT_NODES: &str = r#"
[[node]]
name = "shaft"
tool = "ShaftClassify"
arms = [{ on = "Invisible", to = "stop" }, { on = "Visible", to = "open" }, { on = "Partial", to = "cluster" }]

[[node]]
name = "open"
tool = "ClusterError"
args = ["eps"]
arms = [{ on = "Above", to = "size" }, { on = "Below", to = "open_variation" }]

[[node]]
name = "open_variation"
tool = "SourceVariation"
args = ["eps"]
arms = [{ on = "Above", to = "open_source" }, { on = "Below", to = "link" }]

[[node]]
name = "open_source"
tool = "CanSubdivide"
args = ["min_area"]
arms = [
    { on = "Neither", to = "link" },
    { on = "Emitter", to = "subdivide_emitter" },
    { on = "Receiver", to = "link" },
    { on = "Both", to = "subdivide_emitter" },
]
"#;
    let transfer_to_cluster = r#"arms = [{ on = "No", to = "link" }, { on = "Yes", to = "cluster" }]"#;
    assert!(BF_TOML.contains(transfer_to_cluster), "BF's transfer node goes on to the cluster test");
    let transfer_to_shaft = transfer_to_cluster.replace(r#"to = "cluster" }]"#, r#"to = "shaft" }]"#);
    let shaft_toml = BF_TOML.replacen(transfer_to_cluster, &transfer_to_shaft, 1) + SHAFT_NODES;
    let graph = parse_graph(&shaft_toml, std::path::Path::new("shaft.toml")).expect("valid graph file");
    let dag = DagOracle::new(graph, &[]).expect("built-in tools only");
    assert!(dag.needs().shafts);
    let scene = stairs_with_beam();
    let release = ShaftOracle::new(ShaftOracleParams::default());
    let (a, b) = (pipeline::run(&scene, &release, &Config::default(), &|_| {}), pipeline::run(&scene, &dag, &Config::default(), &|_| {}));
    assert!(b.shaft_classified.iter().sum::<u64>() > 0, "the file's shaft tools classified shafts");
    assert_eq!(a.links.len(), b.links.len());
    let (pa, pb) = (polygon_results(&a.hierarchy, &a.solution), polygon_results(&b.hierarchy, &b.solution));
    assert!(pa.iter().zip(&pb).all(|(x, y)| x.b == y.b), "same decisions give the same solution");
}
