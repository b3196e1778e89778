#!/usr/bin/env bash
# Runs every cargo-fuzz target of fuzz/ (mesh readers, table loaders, trajectory and scene
# parsers) one after the other for a bounded time, and fails if any of them crashes.
#
#   tools/fuzz.sh [SECONDS] [TARGET...]   SECONDS per target (default 30); default: every
#                                         target in fuzz/fuzz_targets/
#
# Installs cargo-fuzz if missing (`cargo install cargo-fuzz --locked`). libFuzzer needs a
# nightly rustc: the installed `nightly` toolchain if there is one, else the stable toolchain
# with RUSTC_BOOTSTRAP=1 (both work on this 2-core machine; the first build takes minutes).
# Builds with debug assertions (overflow checks) and AddressSanitizer.
#
# Seeds are read from fuzz/corpus/<target>/ (committed, never written), with the libFuzzer
# dictionary fuzz/dict/<target>.dict when there is one; the inputs a run adds go to
# fuzz/target/corpus/<target>/, kept from run to run. A crash, panic, leak, timeout
# (> 10 s on one input) or out-of-memory (> 2 GB) writes its input to
# fuzz/artifacts/<target>/; the script prints that path and the command that reproduces it,
# then goes on with the next target and exits 1 at the end.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds="${1:-30}"
if [[ ! "$seconds" =~ ^[1-9][0-9]*$ ]]; then
    echo "usage: tools/fuzz.sh [SECONDS] [TARGET...]  (SECONDS: a positive integer)" >&2
    exit 2
fi
shift || true
if (($# > 0)); then
    targets=("$@")
else
    targets=()
    for f in fuzz/fuzz_targets/*.rs; do
        targets+=("$(basename "$f" .rs)")
    done
fi

# The toolchain: nightly if installed, else stable with the nightly features unlocked.
if rustup toolchain list 2>/dev/null | grep -q '^nightly'; then
    cargo=(cargo +nightly)
else
    cargo=(cargo)
    export RUSTC_BOOTSTRAP=1
fi
if ! cargo fuzz --version >/dev/null 2>&1; then
    echo "installing cargo-fuzz" >&2
    cargo install cargo-fuzz --locked
fi

echo "building the fuzz targets ($("${cargo[@]}" --version))" >&2
"${cargo[@]}" fuzz build --debug-assertions

mkdir -p fuzz/target/logs
failed=()
for t in "${targets[@]}"; do
    mkdir -p "fuzz/target/corpus/$t" "fuzz/corpus/$t"
    log="fuzz/target/logs/$t.log"
    start=$(date +%s)
    dict=()
    if [[ -f "fuzz/dict/$t.dict" ]]; then
        dict=(-dict="fuzz/dict/$t.dict")
    fi
    status=0
    "${cargo[@]}" fuzz run --debug-assertions "$t" "fuzz/target/corpus/$t" "fuzz/corpus/$t" -- \
        -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
        "${dict[@]}" >"$log" 2>&1 || status=$?
    elapsed=$(($(date +%s) - start))
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    last=$(grep -E '^#[0-9]+' "$log" | tail -n 1 || true)
    cov=$(sed -nE 's/.* cov: ([0-9]+).*/\1/p' <<<"$last")
    corp=$(sed -nE 's/.* corp: ([0-9]+\/[0-9]+[a-zA-Z]*).*/\1/p' <<<"$last")
    if ((status == 0)); then
        printf '%-18s ok     %4d s  %9s runs  corpus %-12s cov %s\n' \
            "$t" "$elapsed" "${runs:-?}" "${corp:-?}" "${cov:-?}"
    else
        failed+=("$t")
        artifact=$(sed -nE 's/.*Test unit written to (\S+).*/\1/p' "$log" | tail -n 1)
        printf '%-18s FAILED %4d s  (exit %d; log %s)\n' "$t" "$elapsed" "$status" "$log"
        grep -E -A40 'panicked at|==ERROR|ERROR: libFuzzer|SUMMARY' "$log" | head -n 60 | sed 's/^/    /'
        if [[ -n "$artifact" ]]; then
            echo "    artifact: $artifact"
            echo "    reproduce: ${cargo[*]} fuzz run --debug-assertions $t $artifact"
        fi
    fi
done

if ((${#failed[@]} > 0)); then
    echo "fuzz: ${#failed[@]} target(s) failed: ${failed[*]}" >&2
    exit 1
fi
echo "fuzz: ${#targets[@]} target(s), $seconds s each, no crash" >&2
