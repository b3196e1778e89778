#!/usr/bin/env bash
# Link-time proof that the kernel's step path has no reachable panic
# (tools/nopanic-check/src/main.rs): the build links only if no panic is
# reachable from table load, contact forces and the displacement update.
set -euo pipefail
cd "$(dirname "$0")/.."
table="$(tools/box-table.sh)"
cd tools/nopanic-check
if ! PALPATE_TABLE="$table" cargo build --release 2>build.log; then
    if grep -q "undefined symbol: palpate_step_path_can_panic" build.log; then
        echo "FAIL: a panic is reachable from the kernel's step path (the panic handler was linked)." >&2
    else
        cat build.log >&2
    fi
    exit 1
fi
rm -f build.log
echo "no-panic check: linked, no panic reachable from load, contact_forces, free_displacements, displacements"
