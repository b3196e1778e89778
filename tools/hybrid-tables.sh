#!/usr/bin/env bash
# Builds the three f32 tables of the firmware's hybrid (tools/firmware-m4f/hybrid-scene.toml:
# mesh/box with its top corner cell dynamic) with the host CLI (dev profile: `cargo test
# --workspace` has already built it in CI), `palpate scene tables`, and prints their folder.
# Used by firmware-check.sh --hybrid and nopanic-check.sh.
#
#   tools/hybrid-tables.sh [DIR]    DIR/precomputed.bin, DIR/dynamic.bin, DIR/interface.bin
#                                   (default DIR: target/firmware/hybrid)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-target/firmware/hybrid}"
cargo run -q -p palpate -- scene tables tools/firmware-m4f/hybrid-scene.toml \
    --out-dir "$out" --precision f32 >&2
echo "$(cd "$out" && pwd)"
