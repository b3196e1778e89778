/*
 * Generated from tools/firmware-m4f/sequence.txt (the firmware's scripted
 * contact sequence) by tests/tools/firmware_c.rs; do not edit. Rewrite it
 * with `PALPATE_BLESS=1 cargo test -p palpate-tests --test integration
 * tools::firmware_c`. Each float is the f32 palpate-script parses from the
 * text (what `palpate precomputed replay` solves), as an exact hexadecimal
 * literal.
 */
#ifndef PALPATE_EXAMPLE_SEQUENCE_H
#define PALPATE_EXAMPLE_SEQUENCE_H

#include <stdint.h>

#include "palpate.h"

/* One step of the sequence: its contacts. */
struct sequence_step {
    uint32_t count;
    palpate_contact contacts[PALPATE_MAX_CONTACTS];
};

#define SEQUENCE_STEPS 30u

static const struct sequence_step SEQUENCE[SEQUENCE_STEPS] = {
    /* line 8: 53:0,0,-0.0004 */
    {1, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.a36e2ep-12f}}}},
    /* line 9: 53:0,0,-0.0008 */
    {1, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.a36e2ep-11f}}}},
    /* line 10: 53:0,0,-0.0012 */
    {1, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.3a92a4p-10f}}}},
    /* line 11: 53:0,0,-0.0016 */
    {1, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.a36e2ep-10f}}}},
    /* line 12: 53:0,0,-0.002 */
    {1, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-9f}}}},
    /* line 13: 53:0,0,-0.002 */
    {1, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-9f}}}},
    /* line 14: 53:0,0,-0.002 */
    {1, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-9f}}}},
    /* line 16: 53:0,0,-0.002 58:0,0,-0.0005 */
    {2, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-9f}},
      {PALPATE_CONTACT_KIND_VERTEX, {58, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-11f}}}},
    /* line 17: 53:0,0,-0.002 58:0.0002,0,-0.001 54:-0.0002,0,-0.0005 */
    {3, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-9f}},
      {PALPATE_CONTACT_KIND_VERTEX, {58, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x1.a36e2ep-13f, 0x0p+0f, -0x1.0624dep-10f}},
      {PALPATE_CONTACT_KIND_VERTEX, {54, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {-0x1.a36e2ep-13f, 0x0p+0f, -0x1.0624dep-11f}}}},
    /* line 18: 53:0,0,-0.002 58:0.0004,0,-0.0015 54:-0.0004,0,-0.001 */
    {3, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-9f}},
      {PALPATE_CONTACT_KIND_VERTEX, {58, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x1.a36e2ep-12f, 0x0p+0f, -0x1.89374cp-10f}},
      {PALPATE_CONTACT_KIND_VERTEX, {54, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {-0x1.a36e2ep-12f, 0x0p+0f, -0x1.0624dep-10f}}}},
    /* line 19: 53:0,0,-0.002 58:0.0004,0,-0.0015 54:-0.0004,0,-0.001 */
    {3, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-9f}},
      {PALPATE_CONTACT_KIND_VERTEX, {58, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x1.a36e2ep-12f, 0x0p+0f, -0x1.89374cp-10f}},
      {PALPATE_CONTACT_KIND_VERTEX, {54, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {-0x1.a36e2ep-12f, 0x0p+0f, -0x1.0624dep-10f}}}},
    /* line 22: 53:0,0,-0.002 58:0.0004,0,-0.0015 54:-0.0004,0,-0.001 56,57,61@0.2,0.3,0.5:0,0,-0.0005 */
    {4, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-9f}},
      {PALPATE_CONTACT_KIND_VERTEX, {58, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x1.a36e2ep-12f, 0x0p+0f, -0x1.89374cp-10f}},
      {PALPATE_CONTACT_KIND_VERTEX, {54, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {-0x1.a36e2ep-12f, 0x0p+0f, -0x1.0624dep-10f}},
      {PALPATE_CONTACT_KIND_TRIANGLE, {56, 57, 61}, {0x1.99999ap-3f, 0x1.333334p-2f, 0x1.000000p-1f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-11f}}}},
    /* line 23: 53:0,0,-0.002 58:0.0004,0,-0.0015 54:-0.0004,0,-0.001 56,57,61@0.2,0.3,0.5:0,0,-0.001 */
    {4, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-9f}},
      {PALPATE_CONTACT_KIND_VERTEX, {58, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x1.a36e2ep-12f, 0x0p+0f, -0x1.89374cp-10f}},
      {PALPATE_CONTACT_KIND_VERTEX, {54, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {-0x1.a36e2ep-12f, 0x0p+0f, -0x1.0624dep-10f}},
      {PALPATE_CONTACT_KIND_TRIANGLE, {56, 57, 61}, {0x1.99999ap-3f, 0x1.333334p-2f, 0x1.000000p-1f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-10f}}}},
    /* line 26: 53:0,0,-0.002 0:0,0,-0.001 */
    {2, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-9f}},
      {PALPATE_CONTACT_KIND_VERTEX, {0, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-10f}}}},
    /* line 28: 53:0,0,-0.002 53:0,0,-0.001 */
    {2, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-9f}},
      {PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-10f}}}},
    /* line 30: 53:0,0,-0.002 64:0,0,-0.001 */
    {2, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-9f}},
      {PALPATE_CONTACT_KIND_VERTEX, {64, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-10f}}}},
    /* line 32: 21:0,0,-0.001 */
    {1, {{PALPATE_CONTACT_KIND_VERTEX, {21, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-10f}}}},
    /* line 34: 56,57,61@0.5,0.6,0.1:0,0,-0.001 */
    {1, {{PALPATE_CONTACT_KIND_TRIANGLE, {56, 57, 61}, {0x1.000000p-1f, 0x1.333334p-1f, 0x1.99999ap-4f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-10f}}}},
    /* line 36: 0,1,5@0.2,0.3,0.5:0,0,0.001 */
    {1, {{PALPATE_CONTACT_KIND_TRIANGLE, {0, 1, 5}, {0x1.99999ap-3f, 0x1.333334p-2f, 0x1.000000p-1f}, {0x0p+0f, 0x0p+0f, 0x1.0624dep-10f}}}},
    /* line 38: 53:0,0,-0.0015 58:0.0003,0,-0.001 54:-0.0003,0,-0.0005 56,57,61@0.2,0.3,0.5:0,0,-0.0005 */
    {4, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.89374cp-10f}},
      {PALPATE_CONTACT_KIND_VERTEX, {58, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x1.3a92a4p-12f, 0x0p+0f, -0x1.0624dep-10f}},
      {PALPATE_CONTACT_KIND_VERTEX, {54, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {-0x1.3a92a4p-12f, 0x0p+0f, -0x1.0624dep-11f}},
      {PALPATE_CONTACT_KIND_TRIANGLE, {56, 57, 61}, {0x1.99999ap-3f, 0x1.333334p-2f, 0x1.000000p-1f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-11f}}}},
    /* line 39: 53:0,0,-0.0015 58:0.0002,0,-0.0005 54:-0.0002,0,-0.0002 */
    {3, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.89374cp-10f}},
      {PALPATE_CONTACT_KIND_VERTEX, {58, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x1.a36e2ep-13f, 0x0p+0f, -0x1.0624dep-11f}},
      {PALPATE_CONTACT_KIND_VERTEX, {54, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {-0x1.a36e2ep-13f, 0x0p+0f, -0x1.a36e2ep-13f}}}},
    /* line 40: 53:0,0,-0.0015 58:0.0002,0,-0.0005 */
    {2, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.89374cp-10f}},
      {PALPATE_CONTACT_KIND_VERTEX, {58, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x1.a36e2ep-13f, 0x0p+0f, -0x1.0624dep-11f}}}},
    /* line 41: 53:0,0,-0.001 */
    {1, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-10f}}}},
    /* line 42: 53:0,0,-0.0005 */
    {1, {{PALPATE_CONTACT_KIND_VERTEX, {53, 0, 0}, {0x0p+0f, 0x0p+0f, 0x0p+0f}, {0x0p+0f, 0x0p+0f, -0x1.0624dep-11f}}}},
    /* line 43: - */
    {0, {{0}}},
    /* line 47: 19,23,39@0.3,0.3,0.4:-0.0005,0,0 */
    {1, {{PALPATE_CONTACT_KIND_TRIANGLE, {19, 23, 39}, {0x1.333334p-2f, 0x1.333334p-2f, 0x1.99999ap-2f}, {-0x1.0624dep-11f, 0x0p+0f, 0x0p+0f}}}},
    /* line 48: 19,23,39@0.3,0.3,0.4:-0.001,0,0.0002 */
    {1, {{PALPATE_CONTACT_KIND_TRIANGLE, {19, 23, 39}, {0x1.333334p-2f, 0x1.333334p-2f, 0x1.99999ap-2f}, {-0x1.0624dep-10f, 0x0p+0f, 0x1.a36e2ep-13f}}}},
    /* line 49: 19,23,39@0.3,0.3,0.4:-0.001,0,0.0004 */
    {1, {{PALPATE_CONTACT_KIND_TRIANGLE, {19, 23, 39}, {0x1.333334p-2f, 0x1.333334p-2f, 0x1.99999ap-2f}, {-0x1.0624dep-10f, 0x0p+0f, 0x1.a36e2ep-12f}}}},
    /* line 50: 3,7,23@0.25,0.25,0.5:-0.0005,0,0 */
    {1, {{PALPATE_CONTACT_KIND_TRIANGLE, {3, 7, 23}, {0x1.000000p-2f, 0x1.000000p-2f, 0x1.000000p-1f}, {-0x1.0624dep-11f, 0x0p+0f, 0x0p+0f}}}},
    /* line 51: - */
    {0, {{0}}},
};

#endif /* PALPATE_EXAMPLE_SEQUENCE_H */
