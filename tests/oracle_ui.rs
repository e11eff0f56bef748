//! `oracle!` as users see it: graphs in `ui/ok` must compile; each graph in `ui/err` has one
//! mistake and must fail with the checked-in message (`.stderr`) at the offending token.
//! Compiler messages change between releases, so this runs on the pinned toolchain only
//! (`rust-toolchain.toml`).

#[test]
fn ui() {
    let t = trybuild::TestCases::new();
    t.pass("tests/ui/ok/*.rs");
    t.compile_fail("tests/ui/err/*.rs");
}
