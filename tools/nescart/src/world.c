/* The stages: their ground map in RAM, and the background drawn from it
 * column by column as the camera scrolls. */
#include <string.h>

#include "game.h"

#define TILE_SKY 0x00
#define TILE_GRASS 0x01
#define TILE_DIRT 0x02
#define TILE_POLE 0x03
#define TILE_FLAG 0x04
#define POLE_TILES 10
#define ROWS 30

/* One character a 16-pixel column: '.' a pit, '1'-'4' ground of that
 * height (16 pixels a step, the lowest floor at y 208), 'A'-'D' the same
 * heights with a coin above, 'a'-'d' with a crawler on it.  The goal pole
 * stands five columns before the end.  Every pit is at most three columns
 * wide and has six columns of ground after it to land on; a wall is at most
 * two steps (32 pixels) high. */
static const char *const stages[6] = {
    /* 1-1 */
    "1111111111" "11AAA1111" "..111111" "1111a1111" "1112222221" "11...111111" "11AAA1111" "1a11111"
    "22223333" "3333111111" "..1111111" "b22222BBB2" "2221111111" "a111111" "..111111" "1111111111",
    /* 1-2 */
    "1111111111" "11AA1111" "..111111" "1a11111" "22222222" "..222222" "2b22222" "33333333"
    "1111111" "...111111" "11CCC111" "1a111111" "..1111111" "22223333" "33c333333" "..222222"
    "2222a2222" "1111111111",
    /* 2-1 */
    "1111111111" "1111111" "...111111" "11a11111" "2222..222222" "2BBB22" "33333333" "...3333333"
    "3c333333" "22222222" "...111111" "1a111111" "..1111111" "AAA1111" "2222333333" "...222222"
    "2b22222" "...1111111" "1111111111",
    /* 2-2 */
    "1111111111" "11111a1111" "..111111" "2222..222222" "33333333" "...333333" "3c33333" "CCC33333"
    "44444444" "...222222" "22b22222" "...111111" "1a11111" "1a11111" "..1111111" "22222222"
    "...2222222" "2b22222" "11111111" "...1111111" "1111111111",
    /* 3-1 */
    "1111111111" "1111a11111" "...111111" "22222222" "...22b22222" "33333333" "...33333333"
    "3c33333" "44444444" "...2222222" "22BBB2222" "2b222222" "...111111" "1a111111" "..1111111"
    "2222..2222222" "3333333333" "...2222222" "2b22222" "...1111111" "11a111111" "1111111111",
    /* 3-2 */
    "1111111111" "1111a11111" "...111111" "22222222" "...22b22222" "3333..333333" "44444444"
    "...4444444" "4d44444" "...2222222" "22BBB2222" "2b222222" "...111111" "1a111111" "...1111111"
    "2222...2222222" "3333333333" "...3333333" "3c33333" "...1111111" "11a111111" "...111111"
    "1111111111",
};

/* y of the ground's top by height: 16 pixels a step up from 208. */
static const unsigned char tops[8] = {255, 208, 192, 176, 160, 144, 128, 112};

#define height(column) (ground[column] & 7)

/* y of the ground's top at level x; 255 over a pit (no ground at all). */
int ground_top(unsigned x)
{
    return tops[height((unsigned char)(x >> 4))];
}

static void add_enemy(unsigned char column)
{
    struct enemy *e = ENEMY(enemy_count);
    unsigned char left = column, right = column, h = height(column), n;
    /* Patrol the flat ground around the spawn, up to three columns each way. */
    for (n = 0; n < 3 && left > 0 && height(left - 1) == h; ++n)
        --left;
    for (n = 0; n < 3 && height(right + 1) == h; ++n)
        ++right;
    e->x = column * 16 + 8;
    e->x0 = left * 16 + 4;
    e->x1 = right * 16 + 12;
    e->y = tops[h];
    e->state = ES_WALK;
    e->dir = -1;
    e->pause = 0;
    ++enemy_count;
}

/* Fill the ground map, crawlers and goal of stage (world, stage). */
void load_stage(void)
{
    const char *s = stages[world * 2 + stage];
    unsigned char n = (unsigned char)strlen(s), i;
    char c;
    memset(ground, 0, 256);
    memset(ENEMY(0), 0, MAX_ENEMIES * ENEMY_SIZE);
    enemy_count = 0;
    coin_count = 0;
    for (i = 0; i < n; ++i) {
        c = s[i];
        if (c >= 'A' && c <= 'D') {
            ground[i] = (c - 'A' + 1) | GROUND_COIN;
            ++coin_count;
        } else if (c >= 'a' && c <= 'd') {
            ground[i] = c - 'a' + 1;
        } else if (c >= '1' && c <= '4') {
            ground[i] = c - '0';
        }
    }
    for (i = 0; i < n; ++i)
        if (s[i] >= 'a' && s[i] <= 'd' && enemy_count < MAX_ENEMIES)
            add_enemy(i);
    level_width = n * 16;
    end_x = (n - 5) * 16 + 8;
    start_x = 40;
}

/* Queue the 8-pixel background column `tc` of the stage. */
static void put_column(unsigned tc)
{
    unsigned char *tiles = queue_entry(0x2000 + ((tc & 32) ? 0x400 : 0) + (tc & 31), ROWS, 1);
    unsigned char h = 0, top, r;
    if (tc < (level_width >> 3))
        h = height((unsigned char)(tc >> 1));
    top = h ? tops[h] >> 3 : ROWS;
    for (r = 0; r < top; ++r)
        tiles[r] = TILE_SKY;
    if (r < ROWS)
        tiles[r++] = TILE_GRASS;
    for (; r < ROWS; ++r)
        tiles[r] = TILE_DIRT;
    if (tc == (end_x >> 3) && top >= POLE_TILES) {
        for (r = top - POLE_TILES; r < top; ++r)
            tiles[r] = TILE_POLE;
        tiles[top - POLE_TILES] = TILE_FLAG;
    }
}

/* Draw the whole screen at camera_x, with rendering off. */
void redraw(void)
{
    unsigned char i;
    ppu_off();
    draw_col = camera_x >> 3;
    for (i = 0; i < 33; ++i) {
        put_column(draw_col++);
        queue_flush();
    }
    ppu_on();
}

/* Keep the column just right of the screen drawn as the camera moves. */
void draw_ahead(void)
{
    if (draw_col <= ((camera_x + 256) >> 3))
        put_column(draw_col++);
}
