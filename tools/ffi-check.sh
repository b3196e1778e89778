#!/usr/bin/env bash
# The C ABI (palpate-ffi, ffi/include/palpate.h) on the host. Run from any directory.
# 1. The committed header is what ffi/src generates (tools/ffi-header: cbindgen with
#    ffi/cbindgen.toml); `PALPATE_BLESS=1 tools/ffi-check.sh` rewrites it instead.
# 2. ffi/tests/c/abi_test.c, compiled by the system C compiler (-std=c11 -pedantic,
#    warnings as errors) against the host's libpalpate_ffi.a, passes under valgrind
#    memcheck: every function with real tables (the firmware box's, pre-computed,
#    tensor-mass and hybrid), NULL pointers, short buffers, misaligned tables, handles and
#    memory, handles never created, every kernel refusal with its message, tables
#    corrupted before and after their load, and one solve bit-identical to the host
#    replay's first step. Any failed check or memory error fails the script.
# 3. The C example (tools/firmware-c) built for the host, under valgrind too, replays
#    tools/firmware-m4f/sequence.txt byte-identical to `palpate precomputed replay`.
# Tables and outputs go to target/firmware and target/firmware-c.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
out="$root/target/firmware-c"
mkdir -p "$out"

(cd tools/ffi-header && cargo run -q)

lib="$(tools/ffi-lib.sh)"
table="$(tools/box-table.sh)"
tensor_table="$(tools/box-table.sh --tensor-mass)"
hybrid_tables="$(tools/hybrid-tables.sh)"
replay="$out/host-replay.txt"
tools/palpate.sh precomputed replay "$table" tools/firmware-m4f/sequence.txt >"$replay"

memcheck=(valgrind --tool=memcheck --error-exitcode=1 -q)
cc -std=c11 -pedantic -O1 -g -Wall -Wextra -Werror -Iffi/include ffi/tests/c/abi_test.c "$lib" \
    -lpthread -ldl -lm -o "$out/abi_test"
"${memcheck[@]}" "$out/abi_test" "$table" "$tensor_table" "$hybrid_tables" "$replay"

make -s -C tools/firmware-c host HOST_LIB="$lib" OUT="$out"
"${memcheck[@]}" "$out/palpate-example-host" "$table" >"$out/c-example-host.txt"
if ! grep '^step' "$out/c-example-host.txt" | diff -u "$replay" -; then
    echo "FAIL: the C example on the host and palpate precomputed replay differ" >&2
    exit 1
fi
echo "C example on the host: $(wc -l <"$replay") steps byte-identical to palpate precomputed" \
    "replay, $(grep -c '^tick ' "$out/c-example-host.txt") haptic ticks, valgrind clean"
