/* ARM semihosting calls (semihost.h): `bkpt 0xAB` with the operation in r0
   and a pointer to its arguments (or the argument) in r1. */
#include "semihost.h"

#include <stdint.h>

enum {
    SYS_OPEN = 0x01,
    SYS_WRITE = 0x05,
    SYS_EXIT = 0x18,
    /* SYS_EXIT reasons: QEMU exits 0 for the first, 1 for any other. */
    ADP_STOPPED_APPLICATION_EXIT = 0x20026,
    ADP_STOPPED_RUNTIME_ERROR = 0x20023,
    /* SYS_OPEN mode "w". */
    OPEN_MODE_W = 4,
};

static uintptr_t semihost(uintptr_t operation, const void *argument) {
    register uintptr_t r0 __asm__("r0") = operation;
    register const void *r1 __asm__("r1") = argument;
    __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

void semihost_write(const char *text, size_t len) {
    static intptr_t handle = -1;
    if (handle == -1) {
        const uintptr_t open[3] = {(uintptr_t) ":tt", OPEN_MODE_W, 3};
        handle = (intptr_t)semihost(SYS_OPEN, open);
    }
    const uintptr_t write[3] = {(uintptr_t)handle, (uintptr_t)text, len};
    semihost(SYS_WRITE, write);
}

void semihost_exit(int success) {
    /* AArch32: the reason is the argument itself. */
    semihost(SYS_EXIT, (const void *)(uintptr_t)(success ? ADP_STOPPED_APPLICATION_EXIT
                                                         : ADP_STOPPED_RUNTIME_ERROR));
    for (;;) {
    }
}
