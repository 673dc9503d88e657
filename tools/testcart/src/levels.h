/* Level data: 3 zones x 2 acts, stored compactly in ROM and expanded into
 * the RAM ground map (ADDR_GROUND) when an act starts. */
#ifndef DASHER_LEVELS_H
#define DASHER_LEVELS_H
#include "hw.h"

#define ZONES 3
#define ACTS 2

struct segment {
    u8 cols;   /* run length in 8-pixel columns; 0 ends the list */
    u8 ground; /* GROUND_* byte for every column of the run */
};

struct ring_line {
    u16 col;   /* first ring's column */
    u8 row;    /* cell row, 0 = top of the screen */
    u8 count;  /* rings in a horizontal line; 0 ends the list */
};


struct level {
    u16 start_x, end_x;
    const struct segment *terrain;
    const struct ring_line *rings;
    const u16 *enemies; /* x of each crawler, 0 ends; it patrols the flat
                         * ground around it */
};

extern const struct level levels[ZONES][ACTS];
extern const char *const zone_names[ZONES];

#endif
