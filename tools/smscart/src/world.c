/* Levels: runs of ground and pits, crawlers and coins; the ground map in RAM
 * and its drawing into the 32-column name table as the camera scrolls. */
#include "hopper.h"

typedef struct {
    const uint8_t *runs;      /* (columns, height in tiles; 0 = pit) pairs, ending with 0 */
    const uint8_t *crawlers;  /* (first column, last column) patrols, ending with 0 */
    const uint8_t *coins;     /* (column, tiles above the screen's bottom) pairs, ending with 0 */
} Level;

static const uint8_t runs1[] = {20, 2, 3, 0, 10, 2, 6, 3, 4, 0, 12, 3, 8, 2, 4, 0, 10, 2, 8, 4, 6, 2, 4, 0, 32, 2, 0};
static const uint8_t crawl1[] = {24, 31, 44, 53, 68, 75, 0};
static const uint8_t coins1[] = {21, 6, 41, 6, 65, 6, 93, 6, 28, 5, 36, 6, 49, 6, 59, 5, 72, 5, 81, 7, 88, 5, 0};

static const uint8_t runs2[] = {16, 2, 4, 0, 8, 3, 4, 0, 8, 4, 10, 2, 4, 0, 12, 2, 6, 5, 6, 3, 4, 0, 14, 3, 4, 0, 10, 2, 8, 4, 4, 0, 35, 2, 0};
static const uint8_t crawl2[] = {21, 26, 33, 38, 55, 64, 101, 108, 0};
static const uint8_t coins2[] = {18, 6, 30, 6, 52, 6, 80, 6, 98, 6, 120, 6, 24, 6, 36, 7, 45, 5, 60, 5, 69, 8, 75, 6, 89, 6, 105, 5, 0};

static const uint8_t runs3[] = {16, 2, 4, 0, 6, 2, 4, 0, 10, 3, 8, 5, 4, 0, 10, 5, 6, 3, 4, 0, 12, 2, 8, 4, 6, 6, 4, 0, 14, 3, 4, 0, 8, 2, 4, 0, 10, 4, 4, 0, 38, 2, 0};
static const uint8_t crawl3[] = {31, 38, 41, 46, 53, 60, 85, 90, 103, 114, 121, 126, 0};
static const uint8_t coins3[] = {18, 6, 28, 6, 50, 6, 70, 6, 100, 6, 118, 6, 130, 6, 144, 6, 23, 5, 35, 6, 44, 8, 57, 8, 65, 6, 78, 5, 0};

static const uint8_t runs4[] = {14, 2, 4, 0, 4, 3, 4, 0, 6, 4, 8, 2, 4, 0, 6, 6, 6, 3, 4, 0, 10, 2, 4, 0, 8, 3, 6, 5, 4, 0, 12, 2, 4, 0, 4, 4, 4, 0, 6, 2, 10, 5, 4, 0, 12, 3, 4, 0, 8, 2, 4, 0, 41, 2, 0};
static const uint8_t crawl4[] = {33, 38, 61, 68, 75, 80, 93, 102, 123, 130, 137, 146, 153, 158, 0};
static const uint8_t coins4[] = {16, 6, 24, 6, 42, 6, 58, 6, 72, 6, 90, 6, 106, 6, 114, 6, 134, 6, 150, 6, 162, 6, 29, 7, 36, 5, 47, 9, 0};

static const Level levels[] = {
    {runs1, crawl1, coins1},
    {runs2, crawl2, coins2},
    {runs3, crawl3, coins3},
    {runs4, crawl4, coins4},
};

uint8_t level_count(void)
{
    return sizeof(levels) / sizeof(levels[0]);
}

/* The y of the ground's top at level x (SCREEN_BOTTOM + 64 over a pit). */
int16_t ground_top(uint16_t x)
{
    uint8_t h = G.ground[(uint8_t)(x >> 3)];
    if (x >= G.level_width)
        h = 2;
    return h ? SCREEN_BOTTOM - (h << 3) : SCREEN_BOTTOM + 64;
}

void world_load(uint8_t level)
{
    const Level *l = &levels[level];
    const uint8_t *p;
    uint8_t col = 0, n, i;

    for (p = l->runs; p[0]; p += 2)
        for (n = 0; n < p[0]; n++)
            G.ground[col++] = p[1];
    G.level_width = (uint16_t)col << 3;
    G.end_x = G.level_width - 40;
    G.start_x = 24;

    i = 0;
    for (p = l->crawlers; p[0] && i < MAX_CRAWLERS; p += 2, i++) {
        volatile Crawler *c = &G.crawlers[i];
        c->x0 = ((uint16_t)p[0] << 3) + 4;
        c->x1 = ((uint16_t)p[1] << 3) + 4;
        c->x = c->x1;
        c->state = 2;
        c->pause = 0;
    }
    G.crawler_count = i;

    i = 0;
    for (p = l->coins; p[0] && i < MAX_COINS; p += 2, i++) {
        G.coins[i][0] = p[0];
        G.coins[i][1] = (SCREEN_BOTTOM >> 3) - p[1];
    }
    G.coin_count = i;
}

static void draw_column(uint8_t col)
{
    uint8_t row, tile, i, top = (SCREEN_BOTTOM >> 3) - G.ground[col];
    if (!G.ground[col])
        top = 32;
    for (row = 0; row < 24; row++) {
        tile = row < top ? T_SKY : row == top ? T_GRASS : T_DIRT;
        vdp_put_tile(col, row, tile);
    }
    for (i = 0; i < G.coin_count; i++)
        if (G.coins[i][0] == col && !(G.coins[i][1] & 0x80))
            vdp_put_tile(col, G.coins[i][1], T_COIN);
}

/* One past the last column the window shows. The name table holds 32
 * columns, so on the Master System the column entering at the right shares
 * its place with the one leaving at the left, which the VDP's blanked left
 * column hides. */
static uint16_t columns_wanted(void)
{
    uint16_t want = ((G.camera_x + SCREEN_W - 1) >> 3) + 1;
    return want > (G.level_width >> 3) ? G.level_width >> 3 : want;
}

/* Draw the columns that scroll into view, at most two a frame (the camera
 * moves at most 3 pixels a frame). */
void world_draw_ahead(void)
{
    uint16_t want = columns_wanted();
    uint8_t n = 0;
    while (G.drawn < want && n++ < 2)
        draw_column(G.drawn++);
}

/* Redraw the whole window from the camera (display off: a level start or a respawn). */
void world_redraw(void)
{
    uint16_t want = columns_wanted();
    for (G.drawn = G.camera_x >> 3; G.drawn < want; G.drawn++)
        draw_column(G.drawn);
}
