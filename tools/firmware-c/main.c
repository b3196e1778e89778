/*
 * The C example on the Cortex-M4F (QEMU mps2-an386): the pre-computed table
 * linked into flash (table.S), SysTick at 1 kHz paces the example's steps and
 * ticks (example.c), the console is semihosting. Prints the example's lines,
 * then `#` reports (not compared): the stack's high-water mark and the ticks.
 */
#include <stdint.h>

#include "example.h"
#include "semihost.h"
#include "startup.h"

/* The table in flash (table.S). */
extern const uint8_t palpate_table_start[], palpate_table_end[];

/* SysTick: the processor clock (25 MHz on mps2-an386) divided to 1 kHz. */
#define CPU_HZ 25000000u
#define HAPTIC_HZ 1000u
#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)

static volatile uint32_t ticks;
static uint32_t overruns;

void SysTick_Handler(void) { ticks++; }

void example_write(const char *text, size_t len) { semihost_write(text, len); }

void example_wait_tick(void) {
    static uint32_t seen;
    while (ticks == seen) {
        __asm__ volatile("wfi");
    }
    uint32_t now = ticks;
    overruns += now - seen - 1;
    seen = now;
}

static void put(const char *text) {
    size_t len = 0;
    while (text[len] != '\0') {
        len++;
    }
    semihost_write(text, len);
}

static void put_u32(uint32_t value) {
    char digits[10];
    size_t n = 0;
    do {
        digits[sizeof digits - 1 - n++] = (char)('0' + value % 10);
        value /= 10;
    } while (value != 0);
    semihost_write(digits + sizeof digits - n, n);
}

int main(void) {
    SYST_RVR = CPU_HZ / HAPTIC_HZ - 1;
    SYST_CVR = 0;
    SYST_CSR = 0x7; /* processor clock, interrupt, enabled */
    int status = example_run(palpate_table_start,
                             (size_t)(palpate_table_end - palpate_table_start));
    SYST_CSR = 0;
    put("# stack: high-water mark ");
    put_u32(stack_high_water_bytes());
    put(" bytes of ");
    put_u32(stack_size_bytes());
    put(" (painted at reset, read back now)\n# ticks: ");
    put_u32(ticks);
    put(" SysTick periods of 1 ms, ");
    put_u32(overruns);
    put(" missed by a step that took longer (QEMU runs semihosting output in the guest's time)\n");
    return status;
}
