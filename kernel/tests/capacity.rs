//! The kernel's capacities are checked at compile time (`const { assert!(..) }`
//! in the const-generic constructors and solves): a capacity out of range is a
//! build error naming the bound, not a run-time refusal. Each compile-fail
//! case violates one assert (its `.stderr` snapshot shows the message); the
//! compile-pass case instantiates every checked item at both ends of its
//! range, so that the checks are seen to accept what they must.
//!
//! The `.stderr` snapshots quote the asserting code of the kernel (trybuild
//! writes its paths as `$WORKSPACE/…` without line numbers, so moving it is
//! harmless): after rewording an assert, or with a compiler whose diagnostics
//! read differently, regenerate them with
//! `TRYBUILD=overwrite cargo test -p palpate-kernel --test capacity`
//! and read the diff. The first run builds the kernel and its dependencies
//! once more in `target/tests/trybuild` (a few minutes); later runs take
//! seconds per case.

#[test]
fn capacities_are_checked_at_compile_time() {
    let cases = trybuild::TestCases::new();
    cases.pass("tests/compile_pass/capacity_bounds.rs");
    cases.compile_fail("tests/compile_fail/*.rs");
}
