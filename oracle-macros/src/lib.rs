//! The `oracle!` proc macro: compiles a declared refinement decision graph into one flat,
//! match-based refinement oracle. All the work is in `oracle_graph::dsl` (parse → check → expand).

use proc_macro::TokenStream;

/// Declares refinement oracles as decision graphs; see `oracle_graph::dsl` for the grammar.
///
/// Each `oracle Name { ... }` becomes a `NameParams` struct, a `Name<P = NoProbe>` type that
/// implements `radiosity_core::refine::Oracle` by nested `match`es on its tools' answers (no
/// wildcard arm, so rustc proves every answer handled), and `Name::GRAPH`, the graph as a constant.
#[proc_macro]
pub fn oracle(input: TokenStream) -> TokenStream {
    oracle_graph::dsl::expand(input.into()).into()
}
