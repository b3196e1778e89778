#!/usr/bin/env bash
# The C interface's host static library for the tools' scripts (ffi-check.sh,
# firmware-check.sh --c): `tools/ffi-lib.sh` prints the path of a `libpalpate_ffi.a`
# built for the host. It is the one $PALPATE_FFI_LIB names when set (CI sets it to the
# one `cargo test --workspace` built), else the package's dev-profile build, built first
# if stale.
#
# Why the variable, as for tools/palpate.sh: `cargo build -p palpate-ffi` resolves
# dependency features for that one package (nalgebra and num-traits without `std`), so
# right after the tests it compiles nalgebra, simba, the num crates, the kernel and the
# interface again, a library the tests had just built.
set -euo pipefail
if [[ -n "${PALPATE_FFI_LIB:-}" ]]; then
    if [[ ! -f "$PALPATE_FFI_LIB" ]]; then
        echo "tools/ffi-lib.sh: PALPATE_FFI_LIB=$PALPATE_FFI_LIB is not a file" >&2
        exit 1
    fi
    echo "$PALPATE_FFI_LIB"
else
    root="$(cd "$(dirname "$0")/.." && pwd)"
    (cd "$root" && cargo build -q -p palpate-ffi)
    echo "${CARGO_TARGET_DIR:-$root/target}/debug/libpalpate_ffi.a"
fi
