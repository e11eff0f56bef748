//! The `oracle!` macro as plain functions on token streams (the proc-macro crate only forwards
//! here, so tests can expand and snapshot): [`parse`] → [`check`] → [`expand()`].

pub mod check;
pub mod expand;
pub mod parse;

use proc_macro2::TokenStream;
use quote::quote;

/// Expands the input of `oracle! { ... }`. Errors become `compile_error!`s at the offending
/// tokens, next to the fallback of each failing oracle (its type, params struct and constructors,
/// see [`expand::expand_fallback`]), so user code calling them gets no second wave of errors. Input
/// that does not parse gets the fallback of each oracle [`parse::recover`] finds in it.
#[must_use]
pub fn expand(input: TokenStream) -> TokenStream {
    let (input, syntax_error) = match syn::parse2::<parse::Input>(input.clone()) {
        Ok(i) => (i, None),
        Err(e) => (parse::recover(input), Some(e)),
    };
    let k = match &input.krate {
        Some(p) => quote!(#p),
        None => quote!(::radiosity_core),
    };
    let mut errors = check::Errors::default();
    let models = check::check(&input, &mut errors);
    let mut out = TokenStream::new();
    for m in &models {
        if m.checked.is_some() && syntax_error.is_none() {
            out.extend(expand::expand_oracle(&k, m));
        } else {
            out.extend(expand::expand_fallback(&k, m));
        }
    }
    // After a syntax error the recovered oracles have no nodes: their check errors are not the user's.
    if let Some(e) = syntax_error.or_else(|| errors.take()) {
        out.extend(e.to_compile_error());
    }
    out
}

/// [`expand()`] on source text (for tests and tools); text that does not lex becomes a
/// `compile_error!`.
#[must_use]
pub fn expand_str(src: &str) -> TokenStream {
    match src.parse::<TokenStream>() {
        Ok(tokens) => expand(tokens),
        Err(e) => {
            let msg = format!("oracle! input does not lex: {e}");
            quote!(::core::compile_error!(#msg);)
        }
    }
}
