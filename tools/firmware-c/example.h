/*
 * The C example's portable part: what the Cortex-M4F firmware (main.c) and
 * its host build (host.c) both run, through the C ABI (ffi/include/palpate.h)
 * only. Each platform provides example_write and example_wait_tick.
 */
#ifndef PALPATE_EXAMPLE_H
#define PALPATE_EXAMPLE_H

#include <stddef.h>
#include <stdint.h>

#include "palpate.h"

/* Largest mesh the example's displacement buffer holds, vertices (the box
   of tools/firmware-m4f/mesh: 64). */
#define EXAMPLE_VERTICES 64

/* Writes `len` bytes of output (the platform's: semihosting, stdout). */
void example_write(const char *text, size_t len);

/* Waits for the next 1 kHz haptic tick (the firmware: SysTick; the host:
   returns at once). */
void example_wait_tick(void);

/*
 * Loads the pre-computed table of `len` bytes at `bytes` (16-byte aligned),
 * then, one step per tick:
 * - the scripted sequence (sequence.h, from tools/firmware-m4f/sequence.txt)
 *   through palpate_precomputed_solve and palpate_precomputed_displacements,
 *   one line per step in the format of `palpate precomputed replay`
 *   (`step <i> device <fx> <fy> <fz> contacts <gx> <gy> <gz>... umax <u>` or
 *   `step <i> error <message>`, every float as its f32 bit pattern);
 * - a haptic loop (palpate_precomputed_loop_*): a probe presses the top of
 *   the box, holds, slides, gets a non-finite position (a latched fault),
 *   is reset and lifts off; one line per tick
 *   (`tick <i> force <fx> <fy> <fz> status <s> contacts <n> refused <n>`)
 *   and the displacement field's largest component while it holds
 *   (`field <i> umax <u>`).
 * Returns 0, or 1 after a `# ...` line saying what failed.
 */
int example_run(const uint8_t *bytes, size_t len);

#endif /* PALPATE_EXAMPLE_H */
