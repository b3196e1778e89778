#!/usr/bin/env bash
# Link-time proof that the kernel's step paths have no reachable panic
# (tools/nopanic-check/src/main.rs): the panic handler calls a symbol defined
# nowhere, so the program links only if no panic is reachable, on volatile
# (opaque) inputs, from
# - the pre-computed model: table load, contact forces and the two
#   displacement updates, on the f32 table and on its f16 and q16 compressed
#   versions (blocks dropped in both parts, so both kept-block bitmaps are read);
# - the tensor-mass model: table load, model construction and reset, the
#   per-vertex inputs, the step with each of the four integrators and each
#   elastic law, tet removal, cutting, tearing, the live surface and the
#   outputs, round after round on one model;
# - the haptic loop over each model: construction, tick_tools (probe, grip
#   and blade actions), reset, and for the dynamic model the physics update
#   with its blades, tearing, exposed faces and deforming surface;
# - the hybrid (RR-3510 §6.2): the interface table's load, HybridModel::new,
#   reset, impose, update_background, contact_forces, pass_contact_forces,
#   step with each integrator, displacements; the haptic loop over
#   HybridTissue (new, tick_tools, physics_update, reset);
# - the link's controller (kernel/src/link/): Controller::new, receive on any
#   bytes, tick, command_frame, reset, counters.
# The tables are built from the firmware example's box by tools/box-table.sh
# and (the hybrid's three) tools/hybrid-tables.sh, into target/nopanic (its
# own folder: the firmware checks build theirs into target/firmware).
#
# On failure it rebuilds with `--features locate` (a panic handler that links)
# and lists every call into a panic function with its source line, from the
# line tables of the disassembly.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
tables=target/nopanic
table="$(tools/box-table.sh "$tables/box-table.bin")"
table_f16="$(tools/box-table.sh --compress f16 "$tables/box-table-f16.bin")"
table_q16="$(tools/box-table.sh --compress q16 "$tables/box-table-q16.bin")"
tensor_table="$(tools/box-table.sh --tensor-mass "$tables/box-tensor-table.bin")"
hybrid_tables="$(tools/hybrid-tables.sh "$tables/hybrid")"
export PALPATE_TABLE="$table" PALPATE_TABLE_F16="$table_f16" PALPATE_TABLE_Q16="$table_q16" \
    PALPATE_TENSOR_TABLE="$tensor_table" PALPATE_HYBRID_TABLES="$hybrid_tables"
cd tools/nopanic-check
mkdir -p target
log="$PWD/target/build.log"
elf="$PWD/target/thumbv7em-none-eabihf/release/palpate-nopanic-check"

if cargo build --release 2>"$log"; then
    echo "no-panic check: linked; no panic reachable (volatile inputs) from" \
        "PrecomputedTable::load, contact_forces::<MAX_CONTACTS>, free_displacements," \
        "displacements (f32, f16, q16 and hmatrix tables); TensorMassTable::load, TensorMassModel::new, reset," \
        "set_external_force, set_velocity, impose, release, clear_external_forces," \
        "step (explicit Euler, symplectic Euler, RK4, central difference; linear, St Venant-Kirchhoff," \
        "co-rotational and neo-Hookean, incompressibility on and off), remove_tet, cut_with_tool," \
        "tear, surface_triangles, displacements_m, velocities_m_s, elastic_forces_n, fault;" \
        "HapticLoop::new, tick_tools, reset (pre-computed); DynamicTissue::new, HapticLoop::new," \
        "tick_tools (touch, grip, cut), physics_update (blades, tearing, exposed faces), removed," \
        "reset (tensor-mass, deforming surface); InterfaceTable::load, HybridModel::new, reset," \
        "impose, update_background, contact_forces::<MAX_CONTACTS>, pass_contact_forces, step" \
        "(each integrator), displacements; HybridTissue::new, HapticLoop::new, tick_tools" \
        "(touch, grip, cut), physics_update, removed, reset (hybrid); Controller::new, receive," \
        "tick, command_frame, reset, counters (link)"
    exit 0
fi

if ! grep -q "undefined symbol: palpate_step_path_can_panic" "$log"; then
    cat "$log" >&2
    echo "FAIL: the no-panic check did not build (not a panic path: see the log above)" >&2
    exit 1
fi

cat >&2 <<'EOF'
FAIL: a panic is reachable from the kernel's step path: the panic handler, which
calls the undefined symbol palpate_step_path_can_panic, was linked.
Locating the panic call sites (diagnostic build with --features locate):
EOF
cargo build -q --release --features locate 2>>"$log" || {
    cat "$log" >&2
    exit 1
}
llvm_bin="$(echo "$(rustc --print sysroot)"/lib/rustlib/*/bin)"
# For each call or tail call into a panic function (core::panicking::*,
# *_fail, unwrap_failed...) from code that is not itself a panic function,
# print the enclosing symbol, the innermost source line of the call (exact; in
# core for #[track_caller] functions such as unwrap) and the nearest preceding
# line of this repository in the listing (a hint only: LTO inlines and moves
# code; read the listing around the call to be sure).
listing="$PWD/target/nopanic-listing.txt"
"$llvm_bin/llvm-objdump" -d --line-numbers --demangle --no-show-raw-insn "$elf" >"$listing"
awk -v root="$root/" '
    /^[0-9a-f]+ <.*>:$/ { fn = $0; sub(/^[0-9a-f]+ </, "", fn); sub(/>:$/, "", fn); next }
    /^; \// { line = substr($0, 3); if (index(line, root) == 1) own = substr(line, length(root) + 1); next }
    $2 ~ /^(bl|b|b\.w)$/ && /<core::[^>]*(panic|_fail)/ && fn !~ /^core::/ {
        target = $0; sub(/.*</, "", target); sub(/(\+0x[0-9a-f]+)?>.*/, "", target)
        addr = $1; sub(/:$/, "", addr)
        printf "  %s calls %s at 0x%s\n    innermost line: %s\n    hint, nearest repository line above: %s\n", fn, target, addr, line, own
        found = 1
    }
    END { if (!found) print "  (no call site recognised: read the listing)" }
' "$listing" >&2
echo "annotated listing: $listing; build log: $log" >&2
exit 1
