/* The C example's start-up (startup.c): the painted stack's measurement. */
#ifndef PALPATE_STARTUP_H
#define PALPATE_STARTUP_H

#include <stdint.h>

/* The word the reset handler paints the free stack with. */
#define STACK_PAINT 0xC5C5C5C5u

/* Stack bytes ever used since reset: from the top down to the lowest word
   that no longer holds the paint (the high-water mark). */
uint32_t stack_high_water_bytes(void);

/* The stack's size (mps2-an386.ld). */
uint32_t stack_size_bytes(void);

#endif /* PALPATE_STARTUP_H */
