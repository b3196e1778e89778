#!/usr/bin/env bash
# Builds the Cortex-M4F example with its tables, runs it under QEMU
# (mps2-an386), replays the same sequence on the host with the same tables
# and requires byte-identical output (every f32 as its bit pattern); then
# reports flash and RAM figures. Run from any directory.
#
#   tools/firmware-check.sh            the pre-computed model: box-table.sh's table,
#                                      sequence.txt, vs `palpate precomputed replay`
#   tools/firmware-check.sh --compress CODE
#                                      the same with the table compressed (CODE f16 or
#                                      q16; `box-table.sh --compress CODE`): the kernel
#                                      decodes it on the fly on both sides
#   tools/firmware-check.sh --hybrid   the hybrid (RR-3510 §6.2): hybrid-tables.sh's three
#                                      tables, hybrid-sequence.txt, firmware built with
#                                      `--features hybrid`, vs `palpate scene replay-hybrid`
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
out="$root/target/firmware"
mkdir -p "$out"

if [[ "${1:-}" == --hybrid ]]; then
    mode=hybrid
    tables="$(tools/hybrid-tables.sh)" # host CLI, dev profile; prints the tables' folder
    sequence="$root/tools/firmware-m4f/hybrid-sequence.txt"
    host=(scene replay-hybrid "$tables" "$sequence")
    build=(env PALPATE_HYBRID_TABLES="$tables" cargo build -q --release --features hybrid)
else
    mode=precomputed
    compress=()
    if [[ "${1:-}" == --compress ]]; then
        compress=(--compress "${2:?usage: tools/firmware-check.sh --compress f16|q16}")
        mode="precomputed-$2"
    fi
    table="$(tools/box-table.sh "${compress[@]}")" # host CLI, dev profile; prints the table path
    sequence="$root/tools/firmware-m4f/sequence.txt"
    host=(precomputed replay "$table" "$sequence")
    build=(env PALPATE_TABLE="$table" cargo build -q --release)
fi
host_txt="$out/$mode-host.txt"
firmware_txt="$out/$mode-firmware.txt"

cargo run -q -p palpate -- "${host[@]}" >"$host_txt"

cd tools/firmware-m4f
"${build[@]}"
elf="$PWD/target/thumbv7em-none-eabihf/release/palpate-firmware-m4f"
# The firmware ends QEMU through semihosting (exit status 0 on success); the
# timeout only catches a hang (the whole replay takes well under a second).
status=0
timeout 120 qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic \
    -semihosting-config enable=on,target=native -kernel "$elf" >"$firmware_txt" || status=$?
if [ "$status" != 0 ]; then
    cat "$firmware_txt" >&2
    if [ "$status" = 124 ]; then
        echo "FAIL: the firmware did not exit within 120 s under QEMU" >&2
    else
        echo "FAIL: the firmware exited with status $status under QEMU (output above)" >&2
    fi
    exit 1
fi

# `#` lines are the firmware's own report (table size, contact-state size).
grep '^#' "$firmware_txt" || true
if ! grep -v '^#' "$firmware_txt" | diff -u "$host_txt" -; then
    echo "FAIL: firmware (QEMU, Cortex-M4F) and host (palpate ${host[*]:0:2}) outputs differ ($mode)" >&2
    exit 1
fi
steps="$(wc -l <"$host_txt")"
refused="$(grep -c ' error ' "$host_txt" || true)"
echo "firmware vs host ($mode): $steps steps ($refused refused), bit-identical f32 device and contact forces, largest displacement$([[ $mode == hybrid ]] && echo ', kinetic energy')"

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
