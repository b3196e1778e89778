#!/usr/bin/env bash
# The host CLI for the tools' scripts: `tools/palpate.sh ARGS...` runs `palpate ARGS...`,
# `tools/palpate.sh --path` prints the binary's path. The binary is the one $PALPATE_BIN
# names when set (CI sets it to the one `cargo test --workspace` built), else the
# package's dev-profile build, built first if stale.
#
# Why the variable: `cargo test --workspace` resolves dependency features across every
# member of the workspace and their dev-dependencies, `cargo build -p palpate` for that
# one package (bitflags, either, serde, toml and zerocopy get fewer features), so right
# after the tests the latter compiles faer, its gemm crates and the harness again: about
# 140 s of a fresh CI.
set -euo pipefail
if [[ -n "${PALPATE_BIN:-}" ]]; then
    bin="$PALPATE_BIN"
    if [[ ! -x "$bin" ]]; then
        echo "tools/palpate.sh: PALPATE_BIN=$bin is not an executable" >&2
        exit 1
    fi
else
    root="$(cd "$(dirname "$0")/.." && pwd)"
    (cd "$root" && cargo build -q -p palpate)
    bin="${CARGO_TARGET_DIR:-$root/target}/debug/palpate"
fi
if [[ "${1:-}" == --path ]]; then
    echo "$bin"
else
    exec "$bin" "$@"
fi
