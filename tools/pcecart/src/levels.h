#ifndef LEVELS_H
#define LEVELS_H

#define LEVELS 3
#define FLOOR_HEIGHT 4  /* the usual ground: 4 tiles, its top at y 208 */

struct level {
    const unsigned char *runs;     /* (columns, height in tiles) pairs, 0 columns ends; height 0 is a pit */
    const unsigned char *crawlers; /* (first column, last column) patrol pairs on flat ground, 0 ends */
    const unsigned char *coins;    /* (column, tile row) pairs, 0 ends */
    unsigned end_x;                /* the goal */
};

extern const struct level levels[LEVELS];

#endif
