/* The level in RAM (ground map, crawlers, coins) and in the BAT: the terrain
 * is drawn column by column ahead of the camera, which only moves right. */
#include "art.h"
#include "hw.h"
#include "levels.h"
#include "ram.h"
#include "video.h"
#include "world.h"

#define ROWS 30          /* 240 lines of 8-pixel tiles */
#define AHEAD 33         /* columns drawn past the camera's left edge */

/* The top of the ground at a level x, in screen pixels; NO_FLOOR over a pit. */
int floor_at(int x) {
    unsigned char h;
    if (x < 0) return 0;  /* the level's left end is a wall */
    if ((unsigned)x >= LEVEL_WIDTH) return 240 - 8 * FLOOR_HEIGHT;
    h = GROUND[(unsigned)x >> 3];
    return h ? 240 - 8 * h : NO_FLOOR;
}

void world_load(void) {
    const struct level *lv = &levels[LEVEL];
    const unsigned char *p;
    unsigned col = 0;
    unsigned char i, n;
    for (p = lv->runs; p[0]; p += 2) {
        for (n = 0; n < p[0]; ++n) GROUND[col++] = p[1];
    }
    LEVEL_WIDTH = col << 3;
    END_X = lv->end_x;
    START_X = 32;
    i = 0;
    for (p = lv->crawlers; p[0]; p += 2, ++i) {
        ENEMY[i].x0 = ((unsigned)p[0] << 3) + 8;
        ENEMY[i].x1 = ((unsigned)p[1] << 3);
        ENEMY[i].x = ENEMY[i].x0 + (((unsigned)i * 24) % (ENEMY[i].x1 - ENEMY[i].x0));
        ENEMY[i].y = 240 - 8 * GROUND[p[0]];
        ENEMY[i].state = 1;
        ENEMY[i].dir = (i & 1) ? -1 : 1;
        ENEMY[i].pause = 0;
    }
    ENEMY_COUNT = i;
    i = 0;
    for (p = lv->coins; p[0]; p += 2, ++i) {
        COIN[i].col = p[0];
        COIN[i].row = p[1];
        COIN[i].taken = 0;
    }
    COIN_COUNT = i;
}

static unsigned tile_at(unsigned col, unsigned char row) {
    unsigned char h = GROUND[col], i;
    unsigned goal = END_X >> 3;
    if (h && row == ROWS - h) return T_GRASS | PAL_TERRAIN;
    if (h && row > ROWS - h) return T_DIRT | PAL_TERRAIN;
    if (col == goal && row < ROWS - h && row >= ROWS - h - 10) {
        return (row == ROWS - h - 10 ? T_FLAG : T_POLE) | PAL_TERRAIN;
    }
    for (i = 0; i < COIN_COUNT; ++i) {
        if (COIN[i].col == col && COIN[i].row == row && !COIN[i].taken) return T_COIN | PAL_TERRAIN;
    }
    return T_BLANK;
}

static void draw_column(unsigned col) {
    unsigned char row;
    for (row = 0; row < ROWS; ++row) bat_put((unsigned char)col, row, tile_at(col, row));
}

void world_draw(void) {
    DRAWN_COL = CAMERA_X >> 3;
    world_scroll();
}

void world_scroll(void) {
    unsigned last = (CAMERA_X >> 3) + AHEAD;
    if (last > (LEVEL_WIDTH >> 3)) last = LEVEL_WIDTH >> 3;
    while (DRAWN_COL < last) draw_column(DRAWN_COL++);
}

void camera_follow(void) {
    int target = (int)PX - 112;
    unsigned most = LEVEL_WIDTH - 256;
    if (target > (int)CAMERA_X) CAMERA_X = (unsigned)target;
    if (CAMERA_X > most) CAMERA_X = most;
    world_scroll();
}

void take_coin(unsigned char i) {
    COIN[i].taken = 1;
    bat_put((unsigned char)COIN[i].col, COIN[i].row, T_BLANK);
}
