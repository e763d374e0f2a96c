//! The type-level guarantees of generated code, checked by the compiler:
//! each file in `ui/` must fail to compile with the error in its `.stderr`
//! (the toolchain is pinned, so the messages are stable), and `pass/` holds
//! the correct counterparts, which must compile and run.

#[test]
fn misuse_does_not_compile() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*.rs");
    t.pass("tests/pass/*.rs");
}
