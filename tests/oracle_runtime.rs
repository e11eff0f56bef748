//! The DAG runtime: graph files and their errors, parameters, statistics, execution tracks, and
//! the data manager's promise that a graph without visibility tools casts no ray.

use radiosity::hierarchy::{self, BuildConfig};
use radiosity::oracle::bf::{BF_TOML, BfFlat};
use radiosity::oracle::graph::{BUILTIN_TOOLS, to_dot};
use radiosity::oracle::runtime::{DagOracle, DynTool, GraphBuilder, format_stats, format_trace, load_graph, parse_graph};
use radiosity::oracle::{NoProbe, Recorder};
use radiosity::pipeline::{self, Config};
use radiosity::refine::{Decision, ElementData, LinkCtx, Oracle, Services};
use radiosity::visibility::{RayCaster, VisibilityConfig};
use std::path::Path;

/// Parses `text` as graph file `name` and returns its error text (the test fails if it parses).
fn file_error(name: &str, text: &str) -> String {
    match parse_graph(text, Path::new(name)) {
        Ok(_) => panic!("{name} should be rejected"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn catalogue_lists_each_tools_answers_in_enum_order() {
    for tool in BUILTIN_TOOLS {
        let names = DynTool::answer_names(tool.name).unwrap_or_else(|| panic!("no runtime tool `{}`", tool.name));
        assert_eq!(names, tool.answers, "answers of `{}`", tool.name);
        let args = vec![1.0; tool.args.len()];
        assert!(DynTool::build(tool.name, &args).is_some(), "cannot build `{}`", tool.name);
    }
}

#[test]
fn bf_file_and_bf_macro_are_the_same_graph() {
    let file = parse_graph(BF_TOML, Path::new("bf.toml")).expect("valid");
    let flat = BfFlat::<NoProbe>::GRAPH;
    assert_eq!(file.nodes, flat.nodes);
    assert_eq!(file.params, flat.params);
    assert_eq!(file.start, flat.start);
}

#[test]
fn graph_file_errors_name_file_line_and_node() {
    let head = "name = \"g\"\nstart = \"a\"\n";
    let cycle = format!(
        "{head}[[node]]\nname = \"a\"\ntool = \"Facing\"\narms = [{{ on = \"Yes\", to = \"b\" }}, {{ on = \"No\", to = \"stop\" }}]\n[[node]]\nname = \"b\"\ntool = \"Larger\"\narms = [{{ on = \"Emitter\", to = \"a\" }}, {{ on = \"Receiver\", to = \"link\" }}]\n"
    );
    assert_eq!(file_error("cycle.toml", &cycle), "cycle.toml:10: cycle: `a` -> `b` -> `a`");

    let tool = format!("{head}[[node]]\nname = \"a\"\ntool = \"Facingg\"\narms = [{{ on = \"Yes\", to = \"link\" }}]\n");
    let e = file_error("tool.toml", &tool);
    assert!(e.starts_with("tool.toml:5: unknown tool `Facingg` (tools: BfAbove,"), "{e}");

    let node = format!(
        "{head}[[node]]\nname = \"a\"\ntool = \"Facing\"\narms = [\n  {{ on = \"Yes\", to = \"link\" }},\n  {{ on = \"No\", to = \"elsewhere\" }},\n]\n"
    );
    assert_eq!(file_error("node.toml", &node), "node.toml:8: unknown node `elsewhere`");

    let unmapped = format!(
        "{head}[[node]]\nname = \"a\"\ntool = \"CanSubdivide\"\nargs = [0.0]\narms = [{{ on = \"Neither | Both\", to = \"link\" }}]\n"
    );
    assert_eq!(
        file_error("unmapped.toml", &unmapped),
        "unmapped.toml:4: node `a` does not handle answer(s) `Emitter`, `Receiver` of `CanSubdivide`"
    );

    let foreign = format!(
        "{head}[[node]]\nname = \"a\"\ntool = \"Facing\"\narms = [{{ on = \"Yes | No\", to = \"link\" }}, {{ on = \"Maybe\", to = \"stop\" }}]\n"
    );
    assert_eq!(file_error("foreign.toml", &foreign), "foreign.toml:6: `Maybe` is not an answer of `Facing` (answers: Yes, No)");

    let syntax = "name = \"g\"\nstart = \n";
    assert!(file_error("syntax.toml", syntax).starts_with("syntax.toml:2: "), "{}", file_error("syntax.toml", syntax));

    let unknown_key = format!("{head}[[node]]\nname = \"a\"\ntool = \"Facing\"\nbranches = []\n");
    assert!(
        file_error("key.toml", &unknown_key).starts_with("key.toml:6: unknown field `branches`"),
        "{}",
        file_error("key.toml", &unknown_key)
    );
}

#[test]
fn shared_subgraph_files_are_spliced_and_their_errors_located() {
    let dir = tempfile::tempdir().expect("temp dir");
    let split = "[[node]]\nname = \"size\"\ntool = \"CanSubdivide\"\nargs = [0.0]\narms = [\n  { on = \"Neither\", to = \"link\" },\n  { on = \"Emitter | Receiver | Both\", to = \"subdivide_both\" },\n]\n";
    std::fs::write(dir.path().join("split.toml"), split).expect("write");
    let main = "name = \"m\"\nstart = \"near\"\nuses = [\"split.toml\"]\n[[node]]\nname = \"near\"\ntool = \"ClusterTooNear\"\narms = [{ on = \"Yes\", to = \"size\" }, { on = \"No\", to = \"link\" }]\n";
    std::fs::write(dir.path().join("main.toml"), main).expect("write");
    let g = load_graph(&dir.path().join("main.toml")).expect("valid");
    assert_eq!(g.nodes.iter().map(|n| n.name.to_string()).collect::<Vec<_>>(), ["near", "size"]);

    let broken = split.replace("to = \"link\"", "to = \"nowhere\"");
    std::fs::write(dir.path().join("split.toml"), broken).expect("write");
    let e = load_graph(&dir.path().join("main.toml")).expect_err("broken shared graph").to_string();
    assert!(e.ends_with("split.toml:6: unknown node `nowhere`"), "{e}");
}

#[test]
fn parameters_are_checked_and_listed() {
    let g = parse_graph(BF_TOML, Path::new("bf.toml")).expect("valid");
    let e = DagOracle::new(g.clone(), &[("epsilon".to_owned(), 0.1)]).err().expect("unknown parameter").to_string();
    assert_eq!(e, "unknown parameter `epsilon` of oracle `bf` (parameters: eps: f64 = 0.01 in [0, 1], min_area: f64 = 0 in [0, 1e300])");
    let e = DagOracle::new(g.clone(), &[("eps".to_owned(), 1.5)]).err().expect("out of range").to_string();
    assert_eq!(e, "parameter `eps` = 1.5 is outside [0, 1]");
    let o = DagOracle::new(g, &[("eps".to_owned(), 0.5)]).expect("in range");
    assert_eq!(o.param_values(), [0.5, 0.0]);
    let mut p = radiosity::oracle::bf::BfFlatParams::default();
    assert!(p.set("eps", -0.1).is_err());
    p.set("eps", 0.25).expect("in range");
    assert_eq!(p.eps, 0.25);
}

#[test]
fn statistics_and_trace_of_an_instrumented_run() {
    let scene = radiosity::scene::cornell_box();
    let graph = parse_graph(BF_TOML, Path::new("bf.toml")).expect("valid");
    // First a plain run, to pick a pair that is evaluated in the first pass.
    let config = Config { max_passes: 1, ..Config::default() };
    let plain = pipeline::run(&scene, &DagOracle::new(graph.clone(), &[]).expect("valid"), &config, &|_| {});
    // One of reflected light: partly visible links from an emitter may have been pushed down to
    // leaves after the oracle linked their parents (the irradiance criterion's shadow step), and
    // the oracle never saw those pairs, some of which the light sees whole.
    let decided: Vec<_> = plain.links.iter().filter(|l| l.vis >= 1.0 && !plain.hierarchy.holds_emitter(l.source)).collect();
    let link = *decided[decided.len() / 2];
    let probe = Recorder::new(graph.nodes.len()).tracing(link.source, link.receiver);
    let dag = DagOracle::with_probe(graph.clone(), &[], Vec::new(), probe).expect("valid");
    let solved = pipeline::run(&scene, &dag, &config, &|_| {});
    assert_eq!(solved.links.len(), plain.links.len(), "instrumentation changes nothing");

    let stats = dag.probe().stats(&graph);
    assert_eq!(stats[0].node, "facing");
    assert_eq!(stats[0].calls, solved.refine_stats.oracle_calls, "the start node sees every oracle call");
    let facing_yes = stats[0].answers.iter().find(|(a, _)| a == "Yes").map_or(0, |x| x.1);
    assert_eq!(stats[1].calls, facing_yes, "`near` is reached exactly by facing's `Yes`");
    assert!(format_stats(&stats).contains("facing"));

    let trace = dag.probe().trace();
    assert!(!trace.is_empty(), "the traced pair was evaluated");
    assert_eq!(trace[0].node, 0);
    let text = format_trace(&graph, &trace);
    assert!(text.starts_with("facing: Facing -> Yes => near"), "{text}");
    assert!(text.lines().last().is_some_and(|l| l.contains("=> link")), "the linked pair ends in `link`: {text}");
}

#[test]
fn never_taken_branches_are_reported() {
    let g = GraphBuilder::new("always").start("facing").node("facing", "Facing", &[]).arm(&["Yes"], "link").arm(&["No"], "stop").build();
    let dag = DagOracle::with_probe(g.clone(), &[], Vec::new(), Recorder::new(1)).expect("valid");
    let scene = radiosity::scene::cornell_box();
    let _ = pipeline::run(&scene, &dag, &Config { max_passes: 1, ..Config::default() }, &|_| {});
    let stats = dag.probe().stats(&g);
    // Every pair below the root cluster self-link is a pair of clusters or polygons of a closed box:
    // some face each other, some do not, so both arms are taken.
    assert!(stats[0].never_taken.is_empty(), "{stats:?}");
    let dot = to_dot(&g, None);
    assert!(dot.contains("\"facing\" -> \"link\" [label=\"Yes\"]"), "{dot}");
}

#[test]
fn a_graph_without_visibility_tools_casts_no_ray() {
    let scene = radiosity::scene::cornell_box();
    let h = hierarchy::build(&scene, &BuildConfig::default());
    let caster = RayCaster::new(&scene);
    let data = ElementData::first_guess(&h);
    let services = Services {
        hierarchy: &h,
        caster: Some(&caster),
        visibility: VisibilityConfig::default(),
        data: &data,
        threshold_scale: 1.0,
        shafts: None,
        criterion: Default::default(),
        reflected_rays: VisibilityConfig::default().rays,
    };
    // The energy part of BF: facing, transfer, subdivision; no visibility tool.
    let energy = GraphBuilder::new("energy")
        .start("facing")
        .node("facing", "Facing", &[])
        .arm(&["No"], "stop")
        .arm(&["Yes"], "energy")
        .node("energy", "BfAbove", &[0.01.into()])
        .arm(&["No"], "link")
        .arm(&["Yes"], "size")
        .node("size", "CanSubdivide", &[0.0.into()])
        .arm(&["Neither"], "link")
        .arm(&["Emitter", "Both"], "subdivide_emitter")
        .arm(&["Receiver"], "subdivide_receiver")
        .build();
    let energy = DagOracle::new(energy, &[]).expect("valid");
    let vis = GraphBuilder::new("vis")
        .start("v")
        .node("v", "RayVisibility", &[4.0.into()])
        .arm(&["Visible", "ProbablyVisible"], "link")
        .arm(&["Invisible", "ProbablyInvisible"], "stop")
        .arm(&["Partial", "ProbablyPartial", "TooComplex"], "subdivide_both")
        .build();
    let vis = DagOracle::new(vis, &[]).expect("valid");
    let polygons = 0..h.n_polygons;
    let mut decisions = 0;
    for s in polygons.clone() {
        for r in polygons.clone() {
            if s == r {
                continue;
            }
            let mut ctx = LinkCtx::new(&services, s, r);
            let _ = energy.decide(&mut ctx);
            assert!(ctx.data.visibility.is_none(), "the energy graph stored visibility for {s} -> {r}");
            decisions += 1;
        }
    }
    assert!(decisions > 10);
    assert_eq!(caster.rays_cast(), 0, "the energy graph cast rays");
    let mut ctx = LinkCtx::new(&services, 0, 1);
    let d = vis.decide(&mut ctx);
    assert!(caster.rays_cast() > 0 && ctx.data.visibility.is_some(), "a visibility graph casts rays");
    assert_ne!(d, Decision::SubdivideReceiver);
}

#[test]
fn visibility_study_counts_links_per_threshold_and_few_rays_err_more() {
    let scene = radiosity::oracle::scenes::room_with_objects();
    let mut config = Config { max_passes: 1, ..Config::default() };
    config.build.min_area_rel = 1e-3;
    let solved = pipeline::run(&scene, &radiosity::refine::BfHand::default(), &config, &|_| {});
    let thresholds = [1e-4, 1e-2, 1.0, f64::INFINITY];
    let rows = radiosity::lab::study::visibility_study(&solved, config.visibility, &thresholds);
    assert_eq!(rows.len(), thresholds.len());
    assert_eq!(rows[3].links, solved.links.len() as u64, "an infinite threshold keeps every link");
    for pair in rows.windows(2) {
        assert!(pair[0].links <= pair[1].links, "links below a threshold grow with it: {rows:?}");
    }
    let all = &rows[3];
    assert!(all.error_rate.iter().all(|e| (0.0..=1.0).contains(e)), "{all:?}");
    assert!(all.error_rate[0] > 0.0, "4 rays misclassify some partly occluded links: {all:?}");
    assert!(all.error_rate[2] <= all.error_rate[0], "64 rays err no more than 4: {all:?}");
}
