#!/usr/bin/env bash
# Builds the f32 table of the firmware example's mesh (tools/firmware-m4f/mesh/box.*)
# with the host CLI (dev profile: `cargo test --workspace` has already built it
# in CI) and prints its path. Used by firmware-check.sh and nopanic-check.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-target/firmware/box-table.bin}"
mkdir -p "$(dirname "$out")"
cargo run -q -p palpate -- tables build tools/firmware-m4f/mesh/box.node \
    --young 3000 --poisson 0.45 --fix 'z<0.001' --precision f32 --quiet -o "$out" >&2
echo "$PWD/$out"
