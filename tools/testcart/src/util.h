/* Small helpers: randomness, BCD scores, decimal digits. */
#ifndef DASHER_UTIL_H
#define DASHER_UTIL_H
#include "hw.h"

void rng_stir(void);          /* once per frame: mix the frame counter and pads in */
u16 rng_next(void);           /* a random 16-bit value */
void score_add(u8 *score, u16 bcd); /* score (4 BCD bytes) += up to 4 BCD digits */
void put_decimal(char *out, u16 value, u16 digits);
u8 math_selftest(void);       /* 1 if __mulsi3/__divsi3/... give right answers */

#endif
