//! Shared fixtures for the criterion benches (seeded, deterministic inputs).
