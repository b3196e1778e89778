/*
 * Link roots for the checks of libpalpate_ffi.a on the Cortex-M4F
 * (tools/firmware-check.sh --c), each linked alone with --gc-sections and
 * its table as the entry symbol, so the image holds exactly what the listed
 * functions reach (its .text: their flash cost, the library's own memcpy
 * and the like included):
 * - palpate_haptic_path: what a pre-computed haptic loop runs at the haptic
 *   rate (create it, tick, reset after a fault);
 * - palpate_haptic_path_with_load: the same plus loading and validating
 *   the table (once, at start-up) and its counts;
 * - palpate_every_entry_point: every function of palpate.h. Linked against
 *   the library built with `--features prove-no-panic`, whose panic handler
 *   calls a symbol defined nowhere: it links only if no panic is reachable
 *   from any entry point on any input (a C caller's arguments are opaque to
 *   the compiler).
 */
#include "palpate.h"

typedef void (*entry)(void);

const entry palpate_every_entry_point[] = {
    (entry)palpate_abi_version,
    (entry)palpate_status_message,
    (entry)palpate_error_message,
    (entry)palpate_precomputed_table_load,
    (entry)palpate_tensor_mass_table_load,
    (entry)palpate_interface_table_load,
    (entry)palpate_table_get_info,
    (entry)palpate_precomputed_solve,
    (entry)palpate_precomputed_displacements,
    (entry)palpate_loop_config_default,
    (entry)palpate_precomputed_loop_create,
    (entry)palpate_precomputed_loop_tick,
    (entry)palpate_precomputed_loop_reset,
    (entry)palpate_precomputed_loop_displacements,
    (entry)palpate_dynamic_memory_size,
    (entry)palpate_dynamic_loop_create,
    (entry)palpate_dynamic_loop_tick,
    (entry)palpate_dynamic_loop_physics_update,
    (entry)palpate_dynamic_loop_removed_tets,
    (entry)palpate_dynamic_loop_reset,
    (entry)palpate_dynamic_loop_displacements,
    (entry)palpate_hybrid_memory_size,
    (entry)palpate_hybrid_loop_create,
    (entry)palpate_hybrid_loop_tick,
    (entry)palpate_hybrid_loop_physics_update,
    (entry)palpate_hybrid_loop_removed_tets,
    (entry)palpate_hybrid_loop_reset,
    (entry)palpate_hybrid_loop_displacements,
};

const entry palpate_haptic_path[] = {
    (entry)palpate_precomputed_loop_create,
    (entry)palpate_precomputed_loop_tick,
    (entry)palpate_precomputed_loop_reset,
};

const entry palpate_haptic_path_with_load[] = {
    (entry)palpate_precomputed_table_load,
    (entry)palpate_table_get_info,
    (entry)palpate_precomputed_loop_create,
    (entry)palpate_precomputed_loop_tick,
    (entry)palpate_precomputed_loop_reset,
};
