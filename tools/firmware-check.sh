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
#   tools/firmware-check.sh --organ    the built-in organ (host-harness/assets/organ.msh,
#                                      1118 vertices) in its hierarchical q16 table
#                                      (`--compress hmatrix-q16 --tolerance 3e-3`, under 1 MB),
#                                      organ-sequence.txt (1 to 4 contacts), vs `palpate
#                                      precomputed replay`
#   tools/firmware-check.sh --hybrid [--law LAW]
#                                      the hybrid (RR-3510 §6.2): hybrid-tables.sh's three
#                                      tables, hybrid-sequence.txt, firmware built with
#                                      `--features hybrid`, vs `palpate scene replay-hybrid`;
#                                      the tensor-mass region's law LAW (linear, the scene's,
#                                      by default; stvk, corotational, neo-hookean: the
#                                      firmware gets it in PALPATE_HYBRID_LAW, the host as
#                                      `--law`)
#   tools/firmware-check.sh --c        the C example (tools/firmware-c) on the C ABI
#                                      (palpate-ffi built for thumbv7em-none-eabihf):
#                                      sequence.txt vs `palpate precomputed replay`, its
#                                      haptic-loop lines vs the same C built for the host;
#                                      sizes, stack high-water mark, the pre-computed haptic
#                                      path's flash (target <= 32 KB), and the link-time proof
#                                      that no entry point can panic
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
out="$root/target/firmware"
mkdir -p "$out"

# QEMU's mps2-an386 running ELF $1 with semihosting, output to $2; exits the
# script on failure. The firmware ends QEMU through semihosting (exit status 0
# on success); the timeout only catches a hang (a run takes well under a second).
run_qemu() {
    local status=0
    timeout 120 qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic \
        -semihosting-config enable=on,target=native -kernel "$1" >"$2" || status=$?
    if [ "$status" != 0 ]; then
        cat "$2" >&2
        if [ "$status" = 124 ]; then
            echo "FAIL: the firmware did not exit within 120 s under QEMU" >&2
        else
            echo "FAIL: the firmware exited with status $status under QEMU (output above)" >&2
        fi
        exit 1
    fi
}

# Sizes, bytes, of the output sections named $2... of ELF $1 ("name size" lines).
section_sizes() {
    local elf="$1"
    shift
    arm-none-eabi-size -A "$elf" | awk -v names=" $* " 'index(names, " " $1 " ") { print $1, $2 }'
}

# The C example on the C ABI (tools/firmware-c, palpate-ffi).
c_mode() {
    local c_out="$root/target/firmware-c"
    mkdir -p "$c_out"
    local table host_txt="$out/c-host.txt" firmware_txt="$out/c-firmware.txt"
    table="$(tools/box-table.sh)"
    tools/palpate.sh precomputed replay "$table" tools/firmware-m4f/sequence.txt >"$host_txt"

    # The library for the M4F (release: LTO, panic = "abort"), and again with the
    # link-time proof's panic handler; copied apart (one artifact path per target).
    local thumb="$root/target/thumbv7em-none-eabihf/release/libpalpate_ffi.a"
    cargo build -q -p palpate-ffi --release --target thumbv7em-none-eabihf
    cp "$thumb" "$c_out/libpalpate_ffi.a"
    cargo build -q -p palpate-ffi --release --target thumbv7em-none-eabihf --features prove-no-panic
    cp "$thumb" "$c_out/libpalpate_ffi-proof.a"
    # The same C for the host, for the haptic loop's lines.
    make -s -C tools/firmware-c firmware host TABLE="$table" FFI_LIB="$c_out/libpalpate_ffi.a" \
        HOST_LIB="$(tools/ffi-lib.sh)" OUT="$c_out"

    # No panic reachable from any entry point.
    if ! make -s -C tools/firmware-c no-panic FFI_PROOF_LIB="$c_out/libpalpate_ffi-proof.a" \
        OUT="$c_out" 2>"$c_out/no-panic.log"; then
        cat "$c_out/no-panic.log" >&2
        if grep -q palpate_ffi_panic_is_reachable "$c_out/no-panic.log"; then
            echo "FAIL: a panic is reachable from an entry point of libpalpate_ffi.a (the link" \
                "above needs palpate_ffi_panic_is_reachable; tools/nopanic-check.sh's listing" \
                "method finds the call)" >&2
        fi
        exit 1
    fi
    echo "no-panic: every entry point of palpate.h linked for the Cortex-M4F against a panic" \
        "handler that does not exist (--features prove-no-panic): no panic reachable"

    run_qemu "$c_out/palpate-example.elf" "$firmware_txt"
    "$c_out/palpate-example-host" "$table" >"$c_out/c-example-host.txt"
    grep '^#' "$firmware_txt" || true
    if ! grep '^step' "$firmware_txt" | diff -u "$host_txt" -; then
        echo "FAIL: the C firmware (QEMU, Cortex-M4F) and the host (palpate precomputed replay)" \
            "replays differ" >&2
        exit 1
    fi
    if ! diff -u <(grep -v '^#' "$c_out/c-example-host.txt") <(grep -v '^#' "$firmware_txt"); then
        echo "FAIL: the C example's output differs between the Cortex-M4F (QEMU) and the host" >&2
        exit 1
    fi
    local steps refused ticks
    steps="$(wc -l <"$host_txt")"
    refused="$(grep -c ' error ' "$host_txt" || true)"
    ticks="$(grep -c '^tick ' "$firmware_txt")"
    echo "C firmware vs host: $steps steps ($refused refused) bit-identical to palpate precomputed" \
        "replay; $ticks haptic ticks and the field bit-identical to the same C on the host"

    # Sizes of the example (C, newlib-nano, the library, the table in flash).
    local elf="$c_out/palpate-example.elf"
    section_sizes "$elf" .text .rodata .palpate_table .data .bss .stack |
        awk '{ print "section " $1 ": " $2 " bytes" } $1 == ".data" || $1 == ".bss" { ram += $2 }
             END { print "static RAM (.data + .bss): " ram " bytes (the stack comes on top)" }'
    # Of .text and .rodata, what comes from libpalpate_ffi.a (the map file's input sections).
    awk '
        function hex(s,   i, c, v) { v = 0; s = tolower(substr(s, 3))
            for (i = 1; i <= length(s); i++) { c = index("0123456789abcdef", substr(s, i, 1)) - 1; v = v * 16 + c }
            return v }
        function add(size, file) { if (out == ".text" || out == ".rodata") { total[out] += hex(size); if (file ~ /libpalpate_ffi/) lib[out] += hex(size) } }
        /^\.[A-Za-z_]/ { out = $1; pending = 0; next }
        /^ \.[^ ]+ +0x[0-9a-f]+ +0x[0-9a-f]+ / { add($3, $4); pending = 0; next }
        /^ \.[^ ]+$/ { pending = 1; next }
        pending && /^ +0x[0-9a-f]+ +0x[0-9a-f]+ / { add($2, $3); pending = 0; next }
        { pending = 0 }
        END { printf "of which libpalpate_ffi.a (the kernel, the ABI, core): .text %d of %d bytes, .rodata %d of %d\n",
                lib[".text"], total[".text"], lib[".rodata"], total[".rodata"] }' "$c_out/palpate-example.map"

    # The pre-computed haptic path's flash: images linked from its entry points alone.
    local path with_load
    path="$(section_sizes "$c_out/haptic-path.elf" .text | awk '{ print $2 }')"
    with_load="$(section_sizes "$c_out/haptic-path-with-load.elf" .text | awk '{ print $2 }')"
    # 32 KB: 23 528 bytes before the deep inside check (a tool point inside
    # the body is reported, docs/haptic.md), 25 516 with it, 28 796 with the
    # hierarchical compliance's reader (the contact solve reads a block
    # through the same match over the table's encodings), 32 056 with its q16
    # codes (hmatrix-q16) beside it; the 24 KB target
    # is to be won back with a cheaper check (docs/cycles.md) and an
    # encoding chosen at build time.
    echo "pre-computed haptic path (loop create, tick, reset): .text $path bytes (target <= 32768);" \
        "with the table's load and validation: $with_load bytes"
    if [ "$path" -gt 32768 ]; then
        echo "FAIL: the pre-computed haptic path's .text exceeds 32 KB" >&2
        exit 1
    fi
}

if [[ "${1:-}" == --c ]]; then
    c_mode
    exit 0
fi

if [[ "${1:-}" == --hybrid ]]; then
    law=linear
    if [[ "${2:-}" == --law ]]; then
        law="${3:?usage: tools/firmware-check.sh --hybrid --law linear|stvk|corotational|neo-hookean}"
    fi
    mode=hybrid
    [[ $law == linear ]] || mode="hybrid-$law"
    tables="$(tools/hybrid-tables.sh)" # host CLI (tools/palpate.sh); prints the tables' folder
    sequence="$root/tools/firmware-m4f/hybrid-sequence.txt"
    host=(scene replay-hybrid "$tables" "$sequence" --law "$law")
    build=(env PALPATE_HYBRID_TABLES="$tables" PALPATE_HYBRID_LAW="$law"
        cargo build -q --release --features hybrid)
elif [[ "${1:-}" == --organ ]]; then
    mode=organ-hmatrix-q16
    table="$out/organ-hmatrix-q16.bin"
    tools/palpate.sh tables build host-harness/assets/organ.msh --young 5000 --poisson 0.4 \
        --fix 'z<0.001' --compress hmatrix-q16 --tolerance 3e-3 --quiet -o "$table" >&2
    sequence="$root/tools/firmware-m4f/organ-sequence.txt"
    host=(precomputed replay "$table" "$sequence")
    build=(env PALPATE_TABLE="$table" PALPATE_SEQUENCE="$sequence" PALPATE_VERTICES=1118
        cargo build -q --release)
else
    mode=precomputed
    compress=()
    if [[ "${1:-}" == --compress ]]; then
        compress=(--compress "${2:?usage: tools/firmware-check.sh --compress f16|q16}")
        mode="precomputed-$2"
    fi
    table="$(tools/box-table.sh "${compress[@]}")" # host CLI (tools/palpate.sh); prints the table path
    sequence="$root/tools/firmware-m4f/sequence.txt"
    host=(precomputed replay "$table" "$sequence")
    build=(env PALPATE_TABLE="$table" PALPATE_SEQUENCE="$sequence" PALPATE_VERTICES=64
        cargo build -q --release)
fi
host_txt="$out/$mode-host.txt"
firmware_txt="$out/$mode-firmware.txt"

tools/palpate.sh "${host[@]}" >"$host_txt"

cd tools/firmware-m4f
"${build[@]}"
elf="$PWD/target/thumbv7em-none-eabihf/release/palpate-firmware-m4f"
run_qemu "$elf" "$firmware_txt"

# `#` lines are the firmware's own report (table size, contact-state size).
grep '^#' "$firmware_txt" || true
if ! grep -v '^#' "$firmware_txt" | diff -u "$host_txt" -; then
    echo "FAIL: firmware (QEMU, Cortex-M4F) and host (palpate ${host[*]:0:2}) outputs differ ($mode)" >&2
    exit 1
fi
steps="$(wc -l <"$host_txt")"
refused="$(grep -c ' error ' "$host_txt" || true)"
echo "firmware vs host ($mode): $steps steps ($refused refused), bit-identical f32 device and contact forces, largest displacement$([[ $mode == hybrid* ]] && echo ', kinetic energy')"

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
