use super::local::local_refinement;
use super::stop::Staleness;
use super::*;
use crate::hierarchy::{self, BuildConfig};
use crate::refine::{ElementData, Link};

/// A local level refines the polygon over the target whole, and of a polygon sending it a
/// large share of its light only the element that sends it (not its parent, nor a piece below
/// it, twice); a polygon sending it little is left as it is.
#[test]
fn local_refinement_takes_the_over_polygon_and_where_its_light_comes_from() {
    let scene = crate::scene::cornell_box();
    let mut h = hierarchy::build(&scene, &BuildConfig::default());
    assert!(h.subdivide(1));
    let (a, b) = (h.children_of(1)[0], h.children_of(1)[1]);
    assert!(h.subdivide(a));
    let below_a = h.children_of(a)[0];
    let radiosity = vec![[1.0; 3]; h.len()];
    let link = |source: u32, receiver: u32, ff: f64| Link { source, receiver, ff, vis: 1.0, rays: 0 };
    // Polygon 0 gets 0.5 from `a`, 0.3 from `below_a`, 0.02 from polygon 2; polygon 3 (not
    // over) gets everything from `b`.
    let links = vec![link(a, 0, 0.5), link(below_a, 0, 0.3), link(2, 0, 0.02), link(b, 3, 0.9)];
    let mut over = vec![false; h.n_polygons as usize];
    over[0] = true;
    let (elements, touched) = local_refinement(&h, &links, &radiosity, &over);
    assert_eq!(elements, vec![0, a], "the over polygon and the element sending it light");
    let want: Vec<bool> = (0..over.len()).map(|p| p == 0 || p == 1).collect();
    assert_eq!(touched, want);
}

/// The levels' estimates of Ward's room (percent; the estimate rises once and then falls to the
/// target) never stop the levels; office2's (flat from the third level on while the links grow
/// 2.7 and 3.6 times) stop them after the fourth; levels that change nothing, after two.
#[test]
fn levels_stop_when_the_estimate_stalls_for_two_levels() {
    let run = |estimates: &[f64], change: f64| {
        let mut s = Staleness::default();
        let mut previous = None;
        for (i, &e) in estimates.iter().enumerate() {
            if let Some(cause) = s.push(previous, e, (i > 0).then_some(change), 0.01) {
                return Some((i + 1, cause));
            }
            previous = Some(e);
        }
        None
    };
    assert_eq!(run(&[28.2, 12.2, 14.7, 11.2, 0.41], 0.01), None);
    assert_eq!(run(&[10.42, 8.57, 10.85, 10.78, 10.87], 0.005), Some((4, StopCause::EstimateStalled)));
    assert_eq!(run(&[3.0, 3.0, 3.0], 1e-6), Some((3, StopCause::NoProgress)));
    assert_eq!(run(&[3.0, 2.8, 2.0, 1.9, 1.8], 0.01), Some((5, StopCause::EstimateStalled)));
}

#[test]
fn visibility_methods_are_found_by_their_names() {
    let names: Vec<&str> = VisibilityMethod::ALL.iter().map(|m| m.name()).collect();
    assert_eq!(names, ["rays", "aabb", "obb", "hull"]);
    for m in VisibilityMethod::ALL {
        assert_eq!(VisibilityMethod::from_name(m.name()), Some(m));
    }
    assert_eq!(VisibilityMethod::from_name("bvh"), None);
}

/// Every cluster's first guess is the area-weighted mean of its polygons' (a cluster's children
/// are built after it, so a pass in id order would average children not yet set).
#[test]
fn initial_radiosity_of_clusters_is_the_mean_of_their_polygons() {
    let scene = crate::scene::cornell_box();
    let h = hierarchy::build(&scene, &hierarchy::BuildConfig { max_leaf_polygons: 2, ..Default::default() });
    let b = ElementData::first_guess(&h).radiosity;
    let mut clusters = 0;
    for e in 0..h.len() as u32 {
        let crate::hierarchy::ElementKind::Cluster { poly_start, poly_end } = h.get(e).kind else { continue };
        let members = &h.cluster_polygons[poly_start as usize..poly_end as usize];
        let area: f64 = members.iter().map(|&p| h.get(p).area).sum();
        for c in 0..3 {
            let mean = members.iter().map(|&p| h.get(p).area * b[p as usize][c]).sum::<f64>() / area;
            assert!((b[e as usize][c] - mean).abs() <= 1e-12 * mean.abs().max(1e-300), "cluster {e}: {} vs {mean}", b[e as usize][c]);
        }
        clusters += 1;
    }
    assert!(clusters > 3 && h.get(h.root).is_cluster(), "the test needs nested clusters");
    let top = b[h.root as usize];
    assert!(top.iter().all(|&x| x > 0.0), "the root of a lit scene has a positive first guess: {top:?}");
}

/// Each level's phase times are that level's share of the run's: summed over the levels they give
/// the run's, the leaf operator's within the solve's, and a level with a leaf-resolution solve
/// spends some time building its coefficients.
#[test]
fn level_phase_times_sum_to_the_run_times() {
    let scene = crate::scene::cornell_box();
    let config = Config { target_error: Some(0.05), ..Config::default() };
    let oracle = crate::refine::ClassicBf { eps: 0.05, b_ref: crate::refine::first_guess_max(&scene) };
    let solved = run(&scene, &oracle, &config, &|_| {});
    assert!(solved.levels.len() >= 2, "the test needs several levels: {}", solved.levels.len());
    let sum = |f: fn(&Timings) -> f64| solved.levels.iter().map(|l| f(&l.phases)).sum::<f64>();
    let t = &solved.timings;
    for (name, total, summed) in [
        ("refine", t.refine, sum(|p| p.refine)),
        ("solve", t.solve, sum(|p| p.solve)),
        ("leaf operator", t.leaf_operator, sum(|p| p.leaf_operator)),
        ("estimate", t.estimate, sum(|p| p.estimate)),
    ] {
        assert!((total - summed).abs() <= 1e-9 * total.max(1.0), "{name}: run {total} s, levels {summed} s");
    }
    for l in &solved.levels {
        let p = &l.phases;
        assert!(p.leaf_operator > 0.0 && p.leaf_operator <= p.solve, "leaf operator {} s of solve {} s", p.leaf_operator, p.solve);
    }
}
