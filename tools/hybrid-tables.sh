#!/usr/bin/env bash
# Builds the three f32 tables of the firmware's hybrid (tools/firmware-m4f/hybrid-scene.toml:
# mesh/box with its top corner cell dynamic) with the host CLI (tools/palpate.sh: in CI the
# binary `cargo test --workspace` built), `palpate scene tables`, and prints their folder.
# Used by firmware-check.sh --hybrid and nopanic-check.sh.
#
#   tools/hybrid-tables.sh [DIR]    DIR/precomputed.bin, DIR/dynamic.bin, DIR/interface.bin
#                                   (default DIR: target/firmware/hybrid)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-target/firmware/hybrid}"
tools/palpate.sh scene tables tools/firmware-m4f/hybrid-scene.toml \
    --out-dir "$out" --precision f32 >&2
echo "$(cd "$out" && pwd)"
