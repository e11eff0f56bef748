//! The `oracle!` macro as plain functions on token streams (the proc-macro crate only forwards
//! here, so tests can expand and snapshot): [`parse`] → [`check`] → [`expand()`].

pub mod check;
pub mod expand;
pub mod parse;

use proc_macro2::TokenStream;
use quote::quote;

/// Expands the input of `oracle! { ... }`. Errors become `compile_error!`s at the offending
/// tokens, next to the fallback of each failing oracle (its type, params struct and constructors,
/// see [`expand::expand_fallback`]), so user code calling them gets no second wave of errors.
#[must_use]
pub fn expand(input: TokenStream) -> TokenStream {
    let input: parse::Input = match syn::parse2(input) {
        Ok(i) => i,
        Err(e) => return e.to_compile_error(),
    };
    let k = match &input.krate {
        Some(p) => quote!(#p),
        None => quote!(::radiosity_core),
    };
    let mut errors = check::Errors::default();
    let models = check::check(&input, &mut errors);
    let mut out = TokenStream::new();
    for m in &models {
        if m.checked.is_some() {
            out.extend(expand::expand_oracle(&k, m));
        } else {
            out.extend(expand::expand_fallback(&k, m));
        }
    }
    if let Some(e) = errors.take() {
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
