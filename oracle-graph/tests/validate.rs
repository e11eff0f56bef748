//! The validation rules, one case per rule, through a single `check(graph, expected)` helper.

use oracle_graph::dsl::{check, parse};
use oracle_graph::validate::{builtin_only, validate};
use oracle_graph::{ErrorKind, Graph};

/// The graph of the only oracle in `src` (macro syntax).
fn graph(src: &str) -> Graph {
    let input: parse::Input = syn::parse_str(src).expect("parses");
    let mut errors = check::Errors::default();
    let models = check::check(&input, &mut errors);
    models.into_iter().next().expect("one oracle").graph
}

/// Validates `src` and compares (rule, message) pairs with `expected` (empty: valid).
fn check(src: &str, expected: &[(ErrorKind, &str)]) {
    let got: Vec<(ErrorKind, String)> = match validate(&graph(src), &builtin_only) {
        Ok(_) => Vec::new(),
        Err(es) => es.into_iter().map(|e| (e.kind, e.message)).collect(),
    };
    let expected: Vec<(ErrorKind, String)> = expected.iter().map(|(k, m)| (*k, (*m).to_owned())).collect();
    assert_eq!(got, expected, "for {src}");
}

#[test]
fn a_valid_graph_has_no_error() {
    check("oracle G { start => a; a: Facing { Yes => link, No => stop } }", &[]);
}

#[test]
fn cycles_are_reported_once_with_their_path() {
    check(
        "oracle G { start => a; a: Facing { Yes => b, No => stop } b: Larger { Emitter => c, Receiver => link } c: ClusterTooNear { Yes => a, No => b } }",
        &[(ErrorKind::Cycle, "cycle: `a` -> `b` -> `c` -> `a`"), (ErrorKind::Cycle, "cycle: `b` -> `c` -> `b`")],
    );
}

#[test]
fn unknown_nodes_tools_params_and_answers() {
    check("oracle G { start => x; }", &[(ErrorKind::UnknownNode, "unknown node `x`")]);
    check("oracle G { start => a; a: Facing { Yes => y, No => stop } }", &[(ErrorKind::UnknownNode, "unknown node `y`")]);
    let unknown_tool = validate(&graph("oracle G { start => a; a: Nope { Yes => link } }"), &builtin_only).expect_err("unknown tool");
    assert_eq!(unknown_tool[0].kind, ErrorKind::UnknownTool);
    assert!(unknown_tool[0].message.starts_with("unknown tool `Nope` (tools: BfAbove,"), "{}", unknown_tool[0].message);
    check("oracle G { start => a; a: BfAbove(eps) { Yes => link, No => stop } }", &[(ErrorKind::UnknownParam, "unknown parameter `eps`")]);
    check(
        "oracle G { start => a; a: BfAbove { Yes => link, No => stop } }",
        &[(ErrorKind::ArgumentCount, "tool `BfAbove` takes 1 argument(s) (eps), found 0")],
    );
    check(
        "oracle G { start => a; a: Facing { Yes => link, No => stop, Maybe => stop } }",
        &[(ErrorKind::UnknownAnswer, "`Maybe` is not an answer of `Facing` (answers: Yes, No)")],
    );
}

#[test]
fn arguments_have_the_tools_types() {
    check(
        "oracle G { params { eps: f64 = 0.5 } start => a; a: RayVisibility(eps) { Visible | Invisible | Partial | ProbablyVisible | ProbablyInvisible | ProbablyPartial | TooComplex => link } }",
        &[(ErrorKind::ArgumentType, "argument `rays` of `RayVisibility` is `u32`, parameter `eps` is `f64`")],
    );
    check(
        "oracle G { start => a; a: RayVisibility(2.5) { Visible | Invisible | Partial | ProbablyVisible | ProbablyInvisible | ProbablyPartial | TooComplex => link } }",
        &[(ErrorKind::ArgumentType, "argument `rays` of `RayVisibility` is a count (`u32`), found 2.5")],
    );
}

#[test]
fn slots_are_those_of_the_tools_used() {
    use oracle_graph::Slot;
    let bf = graph("oracle G { params { eps: f64 = 0.1 } start => a; a: BfAbove(eps) { Yes => subdivide_both, No => link } }");
    assert_eq!(oracle_graph::catalogue::slots(&bf), [Slot::FormFactorMax]);
    let vis = graph(
        "oracle G { start => a; a: ReferenceVisibility { Visible => link, Invisible => stop, Partial => b } b: PreciseVisibility(64) { Done => link } }",
    );
    assert_eq!(oracle_graph::catalogue::slots(&vis), [Slot::Visibility]);
}

#[test]
fn every_answer_is_handled_exactly_once() {
    check(
        "oracle G { start => a; a: Facing { Yes => link } }",
        &[(ErrorKind::UnhandledAnswer, "node `a` does not handle answer(s) `No` of `Facing`")],
    );
    check(
        "oracle G { start => a; a: Facing { Yes | No => link, Yes => stop } }",
        &[(ErrorKind::DuplicateAnswer, "answer `Yes` is handled twice in node `a`")],
    );
    check("oracle G { start => a; a: Facing {} }", &[(ErrorKind::EmptyNode, "node `a` has no arms")]);
}

#[test]
fn node_names_are_unique_reachable_and_not_decisions() {
    check(
        "oracle G { start => a; a: Facing { Yes => link, No => stop } a: Facing { Yes => link, No => stop } }",
        &[(ErrorKind::DuplicateNode, "duplicate node `a`")],
    );
    check(
        "oracle G { start => a; a: Facing { Yes => link, No => stop } b: Facing { Yes => link, No => stop } }",
        &[(ErrorKind::UnreachableNode, "node `b` is unreachable from `start`")],
    );
    check(
        "oracle G { start => a; a: Facing { Yes => link, No => stop } link: Facing { Yes => link, No => stop } }",
        &[
            (ErrorKind::ReservedNodeName, "node name `link` is a decision word"),
            (ErrorKind::UnreachableNode, "node `link` is unreachable from `start`"),
        ],
    );
}

#[test]
fn foreign_tools_are_left_to_the_compiler() {
    let g = graph("oracle G { start => a; a: my::Tool { Anything => link } }");
    assert!(validate(&g, &oracle_graph::validate::builtin_or_foreign).is_ok());
    assert!(validate(&g, &builtin_only).is_err());
}

#[test]
fn a_shared_node_is_counted_once_per_arc() {
    let g = graph(
        "oracle G { start => a; a: Facing { Yes => b, No => c } b: Larger { Emitter => c, Receiver => link } c: ClusterTooNear { Yes => link, No => stop } }",
    );
    let checked = validate(&g, &builtin_only).expect("valid");
    assert_eq!(checked.in_degree, [1, 1, 2]);
    assert_eq!(checked.answer_arm[0], [0, 1]);
}
