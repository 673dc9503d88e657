#include "util.h"
#include "ram.h"

/*
 * Randomness: a 16-bit xorshift whose state is stirred with the frame
 * counter and both pads every frame.  Everything random (crawler pauses)
 * therefore depends on what was pressed when, so a delayed START or a sticky
 * action changes the crawlers' timing, while the same inputs from power-on
 * (or from a save state) always replay the same game.
 */
static u16 xorshift(u16 r)
{
    r ^= r << 7;
    r ^= r >> 9;
    r ^= r << 8;
    return r;
}

void rng_stir(void)
{
    u16 pads = ((u16)RAM.pad[0] << 8) | RAM.pad[1];
    RAM.rng = xorshift(RAM.rng ^ (u16)RAM.frame ^ pads ^ 0x2545);
}

u16 rng_next(void)
{
    RAM.rng = xorshift(RAM.rng + 0x9E37);
    return RAM.rng;
}

/* Add a 4-digit BCD value to an 8-digit BCD score, digit by digit. */
void score_add(u8 *score, u16 bcd)
{
    s16 i;
    u16 carry = 0;
    for (i = 3; i >= 0; i--) {
        u16 add = i == 3 ? (bcd & 0xFF) : i == 2 ? (bcd >> 8) : 0;
        u16 lo = (score[i] & 0x0F) + (add & 0x0F) + carry;
        u16 hi = (score[i] >> 4) + (add >> 4);
        if (lo > 9) {
            lo -= 10;
            hi++;
        }
        carry = hi > 9;
        if (carry)
            hi -= 10;
        score[i] = (u8)((hi << 4) | lo);
    }
    if (carry) /* past 99999999: stay there */
        for (i = 0; i < 4; i++)
            score[i] = 0x99;
}

void put_decimal(char *out, u16 value, u16 digits)
{
    while (digits--) {
        out[digits] = (char)('0' + value % 10);
        value /= 10;
    }
}

/* The helpers in lmath.S checked against answers GCC computed at compile
 * time; volatile stops GCC from folding the runtime calls away too. */
u8 math_selftest(void)
{
    volatile s32 a = 123456789, b = -1000, m = 0x12345;
    volatile u32 c = 4000000000UL, d = 70000, e = 7;
    u8 ok = 1;
    ok &= a * b == (s32)(123456789UL * (u32)-1000L); /* low 32 bits */
    ok &= a * m == (s32)(123456789UL * 0x12345UL);
    ok &= a / b == -123456;
    ok &= a % b == 789;
    ok &= -a / (s32)e == -17636684;
    ok &= -a % (s32)e == -1;
    ok &= c / d == 57142;
    ok &= c % d == 60000;
    ok &= c / e == 571428571UL;
    ok &= c % e == 3;
    return ok;
}
