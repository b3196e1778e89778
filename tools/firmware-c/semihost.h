/*
 * ARM semihosting (QEMU `-semihosting-config enable=on,target=native`): the
 * firmware's console and exit, as the Rust firmware's cortex-m-semihosting
 * does it.
 */
#ifndef PALPATE_SEMIHOST_H
#define PALPATE_SEMIHOST_H

#include <stddef.h>

/* Writes `len` bytes to the host's standard output (opened on first use). */
void semihost_write(const char *text, size_t len);

/* Ends the program: QEMU exits with status 0 if `success`, 1 otherwise. */
void semihost_exit(int success) __attribute__((noreturn));

#endif /* PALPATE_SEMIHOST_H */
