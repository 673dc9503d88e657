/*
 * The three levels, as one character per 8-pixel column of ground:
 * '0' a pit, '1'-'5' the floor's height in tiles, 'a'-'e' the same heights
 * with a coin three tiles above the floor.  Each level also lists its
 * walkers' patrols (first and last column) and ends 10 columns before its
 * last column, where the goal post stands.
 */
#include "ram.h"
#include "game.h"

typedef struct {
    const char *map;
    uint8_t walkers;
    const uint8_t *patrols; /* pairs of columns */
} Level;

static const char ground0[] =
    "2222222222222222222222" "000" "222b2222222" "3333333" "0000" "33333c33333" "222222222222"
    "0000" "22222222" "33" "4444444d44" "000" "4444444" "3333" "22222b222222222" "00000" "22222222"
    "2222222222222222222222";
static const uint8_t patrols0[] = {48, 56, 60, 68, 85, 92, 110, 121};

static const char ground1[] =
    "2222222222222222222222" "0000" "222222" "333c333" "4444" "0000" "444444" "33333" "0000" "3333c33333"
    "222222222" "000" "2222" "33" "44" "55555e5555" "00000" "333333333" "0000" "2222b2222222" "00000"
    "22222222222222222222222";
static const uint8_t patrols1[] = {27, 31, 33, 38, 63, 71, 93, 101, 108, 115, 121, 131};

static const char ground2[] =
    "2222222222222222222222" "00000" "2222b22" "3333" "0000" "33c3333" "44" "55555" "00000" "555555"
    "4444444" "000" "3333d33333" "22222" "00000" "222222222" "3333" "00000" "33333333" "444e4444"
    "0000" "444444" "3333333" "2222222222222222222222";
static const uint8_t patrols2[] = {28, 33, 43, 48, 68, 73, 98, 105, 116, 122, 136, 140, 142, 147, 149, 157};

static const Level levels[LEVELS] = {
    {ground0, sizeof(patrols0) / 2, patrols0},
    {ground1, sizeof(patrols1) / 2, patrols1},
    {ground2, sizeof(patrols2) / 2, patrols2},
};

/* Fill the ground map and the walkers of `level`, and the level's extent. */
void load_level_map(void) {
    const Level *lv = &levels[level];
    const char *g = lv->map;
    uint16_t n = 0;
    uint8_t i;
    for (; g[n] && n < MAX_COLUMNS; ++n) {
        char c = g[n];
        ground[n] = c >= 'a' ? (uint8_t)(0x80 | (c - 'a' + 1)) : (uint8_t)(c - '0');
    }
    level_width = n * 8;
    end_x = (n - 10) * 8;
    start_x = 24;
    for (i = 0; i < ENEMY_MAX; ++i) {
        Enemy *e = &enemies[i];
        if (i < lv->walkers) {
            e->x0 = lv->patrols[2 * i] * 8 + 4;
            e->x1 = lv->patrols[2 * i + 1] * 8 + 4;
            e->x = e->x0;
            e->state = 1;
            e->info = 0;
        } else {
            e->state = 0;
        }
    }
    enemy_count = lv->walkers;
}
