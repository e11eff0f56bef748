//! The `oracle!` proc macro (skeleton): it will compile a declared refinement decision graph
//! into one flat, match-based refinement function. Until then it accepts and drops its input.

use proc_macro::TokenStream;

/// Declares a refinement oracle as a decision graph (not implemented yet: expands to nothing).
#[proc_macro]
pub fn oracle(_input: TokenStream) -> TokenStream {
    TokenStream::new()
}
