//! Robustness of the host harness (found by probing as a hostile
//! but realistic user would): outputs that are never lost or half written
//! ([`output`]), inputs and runs bounded before work starts ([`bounds`]),
//! and inputs that once gave a wrong or unusable result with exit 0
//! ([`results`]). Each test reproduces one probe.

mod bounds;
mod output;
mod results;
