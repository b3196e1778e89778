#!/usr/bin/env bash
# Builds the Cortex-M4F example with the firmware table, runs it under QEMU
# (mps2-an386), replays the same sequence on the host with the same table and
# requires byte-identical output; then reports flash and RAM figures.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
table="$(tools/box-table.sh)"
sequence="$root/tools/firmware-m4f/sequence.txt"
out="$root/target/firmware"

cargo run -q -p palpate -- precomputed replay "$table" "$sequence" >"$out/host.txt"

cd tools/firmware-m4f
PALPATE_TABLE="$table" cargo build -q --release
elf="$PWD/target/thumbv7em-none-eabihf/release/palpate-firmware-m4f"
timeout 120 qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic \
    -semihosting-config enable=on,target=native -kernel "$elf" >"$out/firmware.txt"

grep '^#' "$out/firmware.txt" || true
if ! grep -v '^#' "$out/firmware.txt" | diff -u "$out/host.txt" -; then
    echo "FAIL: firmware (QEMU) and host outputs differ" >&2
    exit 1
fi
echo "firmware vs host: $(wc -l <"$out/host.txt") steps, bit-identical f32 device and contact forces and largest displacement"

llvm_bin="$(echo "$(rustc --print sysroot)"/lib/rustlib/*/bin)"
"$llvm_bin/llvm-size" -A "$elf" | awk '$1 ~ /^\.(vector_table|text|rodata|data|bss)$/ { print "section " $1 ": " $2 " bytes" }'
"$llvm_bin/llvm-nm" --size-sort --demangle --radix=d -S "$elf" | awk '
    $3 ~ /^[tT]$/ { total += $2 + 0 }
    $3 ~ /^[tT]$/ && /palpate_kernel/ { kernel += $2 + 0 }
    $3 ~ /^[tT]$/ && /nalgebra/ { nalgebra += $2 + 0 }
    END {
        printf "functions in .text: %d bytes; named palpate_kernel: %d bytes, nalgebra: %d bytes\n", total, kernel, nalgebra
        print "(lower bounds: LTO inlines kernel code into its callers, e.g. main)"
    }'
