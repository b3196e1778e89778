#!/usr/bin/env bash
# The host CLI for the tools' scripts: `tools/palpate.sh ARGS...` runs `palpate ARGS...`,
# `tools/palpate.sh --path` prints the binary's path. The binary is the one $PALPATE_BIN
# names when set (CI sets it to the one `cargo test --workspace` built), else the
# package's dev-profile build, built first if stale.
#
# Why the variable: `cargo build -p palpate` resolves features for that one package,
# without the test build's dev-dependencies (bitflags, either, serde, toml and zerocopy
# get fewer features), so right after `cargo test --workspace` it compiles faer, its
# gemm crates and the harness again: about 140 s of a fresh CI.
set -euo pipefail
if [[ -n "${PALPATE_BIN:-}" ]]; then
    bin="$PALPATE_BIN"
else
    root="$(cd "$(dirname "$0")/.." && pwd)"
    (cd "$root" && cargo build -q -p palpate)
    bin="$root/target/debug/palpate"
fi
if [[ "${1:-}" == --path ]]; then
    echo "$bin"
else
    exec "$bin" "$@"
fi
