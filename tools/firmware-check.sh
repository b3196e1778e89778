#!/usr/bin/env bash
# Builds the Cortex-M4F example with the firmware table, runs it under QEMU
# (mps2-an386), replays the same sequence on the host with the same table and
# requires byte-identical output (every f32 as its bit pattern); then reports
# flash and RAM figures. Run from any directory.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
table="$(tools/box-table.sh)" # host CLI, dev profile; prints the table path
sequence="$root/tools/firmware-m4f/sequence.txt"
out="$root/target/firmware"
mkdir -p "$out"

cargo run -q -p palpate -- precomputed replay "$table" "$sequence" >"$out/host.txt"

cd tools/firmware-m4f
PALPATE_TABLE="$table" cargo build -q --release
elf="$PWD/target/thumbv7em-none-eabihf/release/palpate-firmware-m4f"
# The firmware ends QEMU through semihosting (exit status 0 on success); the
# timeout only catches a hang (the whole replay takes well under a second).
status=0
timeout 120 qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic \
    -semihosting-config enable=on,target=native -kernel "$elf" >"$out/firmware.txt" || status=$?
if [ "$status" != 0 ]; then
    cat "$out/firmware.txt" >&2
    if [ "$status" = 124 ]; then
        echo "FAIL: the firmware did not exit within 120 s under QEMU" >&2
    else
        echo "FAIL: the firmware exited with status $status under QEMU (output above)" >&2
    fi
    exit 1
fi

# `#` lines are the firmware's own report (table size, contact-state size).
grep '^#' "$out/firmware.txt" || true
if ! grep -v '^#' "$out/firmware.txt" | diff -u "$out/host.txt" -; then
    echo "FAIL: firmware (QEMU, Cortex-M4F) and host (palpate precomputed replay) outputs differ" >&2
    exit 1
fi
steps="$(wc -l <"$out/host.txt")"
refused="$(grep -c ' error ' "$out/host.txt" || true)"
echo "firmware vs host: $steps steps ($refused refused), bit-identical f32 device and contact forces and largest displacement"

llvm_bin="$(echo "$(rustc --print sysroot)"/lib/rustlib/*/bin)"
"$llvm_bin/llvm-size" -A "$elf" | awk '
    $1 ~ /^\.(vector_table|text|rodata|data|bss|uninit)$/ { print "section " $1 ": " $2 " bytes" }
    $1 ~ /^\.(data|bss|uninit)$/ { ram += $2 }
    END { print "static RAM (.data + .bss + .uninit): " ram " bytes (the stack comes on top)" }'
text="$("$llvm_bin/llvm-size" -A "$elf" | awk '$1 == ".text" { print $2 }')"
"$llvm_bin/llvm-nm" --size-sort --demangle --radix=d -S "$elf" | awk -v text="$text" '
    $3 ~ /^[tT]$/ { total += $2 + 0 }
    $3 ~ /^[tT]$/ && /palpate_kernel/ { kernel += $2 + 0 }
    $3 ~ /^[tT]$/ && /nalgebra/ { nalgebra += $2 + 0 }
    END {
        printf "functions in .text: %d bytes; named palpate_kernel: %d bytes (%.0f%% of .text), nalgebra: %d bytes\n",
            total, kernel, 100 * kernel / text, nalgebra
        print "(lower bounds: LTO inlines kernel and nalgebra code into its callers, e.g. main)"
    }'
