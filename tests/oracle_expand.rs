//! Snapshots of what `oracle!` generates (pretty-printed), of its errors, and of the DOT export.

use oracle_graph::dsl::expand_str;

/// Expands `src`, pretty-prints the result and compares it with the stored snapshot `name`.
fn check_expansion(name: &str, src: &str) {
    let out = expand_str(src);
    let file: syn::File = syn::parse2(out.clone()).unwrap_or_else(|e| panic!("{name}: expansion does not parse: {e}\n{out}"));
    insta::assert_snapshot!(name, prettyplease::unparse(&file));
}

#[test]
fn bf_graph_expansion() {
    check_expansion(
        "bf",
        r#"
            /// The classic BF refiner.
            pub oracle Bf {
                params { eps: f64 = 0.01 in 0.0..=1.0, min_area: f64 = 0.0 in 0.0..=1e300 }
                start => facing;
                facing: Facing { No => stop, Yes => near }
                near: ClusterTooNear { Yes => size, No => energy }
                energy: BfAbove(eps) { No => link, Yes => size }
                size: CanSubdivide(min_area) {
                    Neither => link,
                    Emitter => subdivide_emitter,
                    Receiver => subdivide_receiver,
                    Both => larger,
                }
                larger: Larger { Emitter => subdivide_emitter, Receiver => subdivide_receiver }
            }
        "#,
    );
}

#[test]
fn shared_subgraph_expansion() {
    check_expansion(
        "shared",
        r#"
            crate = ::radiosity;

            /// Subdivide what can be, the larger first.
            shared split {
                size: CanSubdivide(0.0) {
                    Neither => link,
                    Emitter => subdivide_emitter,
                    Receiver => subdivide_receiver,
                    Both => larger,
                }
                larger: Larger { Emitter => subdivide_emitter, Receiver => subdivide_receiver }
            }

            /// Visibility first, then energy; the split is reached from three arcs.
            pub oracle VisBf {
                params {
                    eps: f64 = 0.01 in 0.0..=1.0,
                    rays: u32 = 4 in 1..=256,
                    small: f64 = computed |ctx| 0.01 * ctx.receiver_element().area,
                }
                use split;
                start => facing;
                facing: Facing { No => stop, Yes => visible }
                visible: RayVisibility(rays) {
                    Invisible | ProbablyInvisible => stop,
                    Visible | ProbablyVisible => energy,
                    Partial | ProbablyPartial | TooComplex => size,
                }
                energy: BfAbove(eps) { No => link, Yes => tiny }
                tiny: ProjectedAreaBelow(small) { Yes => size, No => size_again }
                size_again: Mark(1) { Done => size }
            }

            /// A second oracle reusing the same branch.
            pub oracle Plain {
                use split;
                start => near;
                near: ClusterTooNear { Yes => size, No => link }
            }
        "#,
    );
}

#[test]
fn errors_are_collected_not_just_the_first() {
    let out = expand_str(
        r#"
        oracle Broken {
            start => a;
            a: Facing { Yes => b, No => ghost }
            b: Facing { Yes => a, No => stop }
            lost: Larger { Emitter => link }
        }
        "#,
    )
    .to_string();
    for needle in [
        "unknown node `ghost`",
        "cycle: `a` -> `b` -> `a`",
        "node `lost` is unreachable from `start`",
        "does not handle answer(s) `Receiver`",
    ] {
        assert!(out.contains(needle), "missing {needle:?} in {out}");
    }
}

#[test]
fn fallback_expansion_of_an_invalid_graph() {
    // The error next to everything user code calls: params, type, constructors, `GRAPH`, `Oracle`.
    check_expansion(
        "fallback",
        r#"
            crate = ::radiosity;

            /// BF with a node that forgets two answers.
            pub oracle Partial {
                params { eps: f64 = 0.01 in 0.0..=1.0, min_area: f64 = 0.0 }
                start => energy;
                energy: BfAbove(eps) { No => link, Yes => size }
                size: CanSubdivide(min_area) { Neither => link, Both => subdivide_both }
            }
        "#,
    );
}

#[test]
fn a_syntax_error_still_gives_the_oracles_it_can_find() {
    let out = expand_str(
        r#"
        crate = ::radiosity;
        pub(crate) oracle First {
            params { eps: f64 = 0.01 in 0.0..=1.0, rays: u32 = 4 }
            start => a;
            a: Facing { Yes => link No => stop }
        }
        oracle Second { start => a; a: Facing { Yes => link, No => stop } }
        "#,
    );
    let file: syn::File = syn::parse2(out.clone()).unwrap_or_else(|e| panic!("fallback does not parse: {e}\n{out}"));
    let text = prettyplease::unparse(&file);
    assert_eq!(text.matches("compile_error!").count(), 1, "only the syntax error is reported:\n{text}");
    assert!(text.contains("expected `,`"), "{text}");
    for needle in [
        "pub(crate) struct FirstParams {",
        "pub eps: f64,",
        "pub rays: u32,",
        "pub(crate) struct First<P = ::radiosity::oracle::NoProbe>",
        "struct SecondParams {}",
        "struct Second<P = ::radiosity::oracle::NoProbe>",
        "pub fn new(params: SecondParams) -> Self",
        "pub fn with_probe(params: FirstParams, probe: P) -> Self",
    ] {
        assert!(text.contains(needle), "missing {needle:?} in\n{text}");
    }
}

#[test]
fn bf_graph_dot() {
    use radiosity::oracle::bf::BfFlat;
    insta::assert_snapshot!("bf_dot", oracle_graph::to_dot(&BfFlat::<radiosity::oracle::NoProbe>::GRAPH, None));
}
