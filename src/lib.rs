//! `radiosity`: the facade crate. Re-exports the library and the `oracle!` macro.

pub use oracle_macros::oracle;
pub use radiosity_core::*;
