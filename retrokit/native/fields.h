/*
 * Decoding RAM fields by a precompiled plan: one call reads every field.
 *
 * The plan is built in Python (retrokit/host/memory.py) from the game's type
 * codes and the system's byte order; here each row is only gathered and decoded.
 */
#ifndef RETROKIT_FIELDS_H
#define RETROKIT_FIELDS_H

#include <stdint.h>

/* Columns of a field plan row. Offsets run from least to most significant byte. */
enum { RK_PLAN_BUFFER = 0, RK_PLAN_WIDTH = 1, RK_PLAN_KIND = 2, RK_PLAN_MASK = 3, RK_PLAN_OFFSETS = 4,
       RK_PLAN_COLUMNS = 12 };

enum { RK_KIND_UNSIGNED = 0, RK_KIND_SIGNED = 1, RK_KIND_BCD = 2, RK_KIND_LOW_BCD = 3 };

/* A BCD byte's two digits; nibbles above 9 wrap as Gym Retro's reader does. */
static inline int64_t rk_bcd_byte(unsigned b) { return (int64_t)((b & 0xF) % 10 + ((b >> 4) % 10) * 10); }

/* Decode one plan row (inline: it runs for every field of every step); the caller has checked its indices. */
static inline int64_t rk_decode_field(const uint8_t *const *buffers, const int64_t *row) {
    const uint8_t *buf = buffers[row[RK_PLAN_BUFFER]];
    int width = (int)row[RK_PLAN_WIDTH];
    int kind = (int)row[RK_PLAN_KIND];
    const int64_t *offsets = row + RK_PLAN_OFFSETS;
    int64_t value = 0;
    switch (kind) {
    case RK_KIND_UNSIGNED:
    case RK_KIND_SIGNED: {
        uint64_t raw = 0;
        for (int i = width - 1; i >= 0; i--) raw = (raw << 8) | buf[offsets[i]];
        if (kind == RK_KIND_SIGNED && width < 8) {
            int shift = 64 - 8 * width;
            value = (int64_t)(raw << shift) >> shift;
        } else {
            value = (int64_t)raw;
        }
        break;
    }
    case RK_KIND_BCD:
        for (int i = width - 1; i >= 0; i--) value = value * 100 + rk_bcd_byte(buf[offsets[i]]);
        break;
    case RK_KIND_LOW_BCD:
        for (int i = width - 1; i >= 0; i--) value = value * 10 + (buf[offsets[i]] & 0xF) % 10;
        break;
    }
    return value & row[RK_PLAN_MASK];
}

#endif
