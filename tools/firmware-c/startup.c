/*
 * Start-up of the C example on QEMU's mps2-an386 (Cortex-M4F): the vector
 * table, the reset handler (FPU on, .data copied, .bss zeroed, the stack
 * painted), SysTick and the fault handlers. The symbols come from
 * mps2-an386.ld.
 */
#include <stdint.h>

#include "startup.h"

#include "semihost.h"

extern uint32_t _sidata[], _sdata[], _edata[], _sbss[], _ebss[];
extern uint32_t _stack_bottom[], _stack_top[];

int main(void);
void Reset_Handler(void);
void SysTick_Handler(void);

/* Coprocessor Access Control Register: CP10 and CP11 (the FPU). */
#define CPACR (*(volatile uint32_t *)0xE000ED88u)

/* A fault: say so on the console and end with failure. */
static void Fault_Handler(void) {
    static const char text[] = "# fault: unexpected exception\n";
    semihost_write(text, sizeof text - 1);
    semihost_exit(0);
}

/* The vector table: initial stack pointer, then the 15 system exceptions
   (reset, NMI, hard fault, ..., SysTick); no device interrupt is used. */
__attribute__((section(".vector_table"), used)) static void (*const vectors[16])(void) = {
    (void (*)(void))_stack_top,
    Reset_Handler,
    Fault_Handler, /* NMI */
    Fault_Handler, /* HardFault */
    Fault_Handler, /* MemManage */
    Fault_Handler, /* BusFault */
    Fault_Handler, /* UsageFault */
    0,
    0,
    0,
    0,
    Fault_Handler, /* SVCall */
    Fault_Handler, /* DebugMonitor */
    0,
    Fault_Handler, /* PendSV */
    SysTick_Handler,
};

void Reset_Handler(void) {
    /* Full access to the FPU before any float instruction (the library is
       built for the hard-float ABI). */
    CPACR |= 0xFu << 20;
    __asm__ volatile("dsb\n\tisb" ::: "memory");
    for (uint32_t *src = _sidata, *dst = _sdata; dst < _edata;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = _sbss; dst < _ebss;) {
        *dst++ = 0;
    }
    /* Paint the free stack, below the current stack pointer. A volatile
       store, so the compiler keeps the loop here instead of calling memset,
       whose own frame would be below the stack pointer and painted over. */
    uint32_t *sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    for (volatile uint32_t *word = _stack_bottom; word < sp; word++) {
        *word = STACK_PAINT;
    }
    semihost_exit(main() == 0);
}

uint32_t stack_high_water_bytes(void) {
    const uint32_t *word = _stack_bottom;
    while (word < _stack_top && *word == STACK_PAINT) {
        word++;
    }
    return (uint32_t)((uintptr_t)_stack_top - (uintptr_t)word);
}

uint32_t stack_size_bytes(void) { return (uint32_t)((uintptr_t)_stack_top - (uintptr_t)_stack_bottom); }
