#!/usr/bin/env bash
# Builds the f32 table of the firmware example's mesh (tools/firmware-m4f/mesh/box.*)
# with the host CLI (tools/palpate.sh: in CI the binary `cargo test --workspace`
# built) and prints its path. Used by firmware-check.sh and nopanic-check.sh.
#
#   tools/box-table.sh [OUT]                  pre-computed table (default OUT:
#                                             target/firmware/box-table.bin)
#   tools/box-table.sh --tensor-mass [OUT]    tensor-mass table, density 1000 kg/m3
#                                             (default OUT: target/firmware/box-tensor-table.bin)
#   tools/box-table.sh --compress CODE [OUT]  pre-computed table compressed, CODE f16 or q16,
#                                             with blocks dropped below 0.2 of their columns'
#                                             largest in both parts (--contact-blocks dropped),
#                                             so that both kept-block bitmaps are exercised
#                                             (default OUT: target/firmware/box-table-CODE.bin);
#                                             CODE hmatrix: the hierarchical table (default
#                                             tolerance, nothing dropped); hmatrix-q16: the
#                                             same in 16-bit codes
set -euo pipefail
cd "$(dirname "$0")/.."
kind=(--kind precomputed)
out_default=target/firmware/box-table.bin
if [[ "${1:-}" == --tensor-mass ]]; then
    shift
    kind=(--kind tensor-mass --density 1000)
    out_default=target/firmware/box-tensor-table.bin
elif [[ "${1:-}" == --compress ]]; then
    code="${2:?usage: tools/box-table.sh --compress f16|q16|hmatrix|hmatrix-q16 [OUT]}"
    shift 2
    if [[ "$code" == hmatrix || "$code" == hmatrix-q16 ]]; then
        kind=(--kind precomputed --compress "$code")
    else
        kind=(--kind precomputed --compress "$code" --drop-below 0.2 --contact-blocks dropped)
    fi
    out_default="target/firmware/box-table-$code.bin"
fi
out="${1:-$out_default}"
mkdir -p "$(dirname "$out")"
tools/palpate.sh tables build tools/firmware-m4f/mesh/box.node \
    --young 3000 --poisson 0.45 --fix 'z<0.001' --precision f32 "${kind[@]}" --quiet -o "$out" >&2
echo "$PWD/$out"
