#ifndef RETROKIT_FIELDS_H
#define RETROKIT_FIELDS_H

#include <stdint.h>

/* Columns of a field plan row. Offsets run from least to most significant byte. */
enum { RK_PLAN_BUFFER = 0, RK_PLAN_WIDTH = 1, RK_PLAN_KIND = 2, RK_PLAN_MASK = 3, RK_PLAN_OFFSETS = 4,
       RK_PLAN_COLUMNS = 12 };

enum { RK_KIND_UNSIGNED = 0, RK_KIND_SIGNED = 1, RK_KIND_BCD = 2, RK_KIND_LOW_BCD = 3 };

/* Decode one plan row; the caller has checked buffer indices and offsets. */
int64_t rk_decode_field(const uint8_t *const *buffers, const int64_t *row);

#endif
