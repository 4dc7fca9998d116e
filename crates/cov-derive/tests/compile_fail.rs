//! The mistakes a third party makes with `#[derive(OperatorSpec)]`, compiled as they would
//! be: each error names the fix (`tests/ui/*.stderr` hold the messages).
//! `TRYBUILD=overwrite cargo test -p cov-derive --test compile_fail` rewrites them after a
//! deliberate change.

#[test]
fn derive_mistakes_get_messages_that_name_the_fix() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*.rs");
}
