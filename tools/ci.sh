#!/usr/bin/env bash
# The whole CI, runnable locally exactly as CI runs it: `tools/ci.sh`.
# `.ci/run` only calls this script.
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n=== %s (%ss)\n' "$*" "$SECONDS"; }

step "setup: targets, components, qemu"
tools/setup.sh

step "format"
cargo fmt --all -- --check
for crate in tools/firmware-m4f tools/nopanic-check; do
    (cd "$crate" && cargo fmt -- --check)
done

step "clippy"
cargo clippy --workspace --all-targets -- -D warnings

step "tests (the README's test command)"
cargo test --workspace

step "kernel cross-builds"
cargo build -p palpate-kernel --release --target thumbv7em-none-eabihf
cargo build -p palpate-kernel --release --target x86_64-unknown-none

step "no-panic link check"
tools/nopanic-check.sh

step "firmware under QEMU vs host"
tools/firmware-check.sh

step "done"
