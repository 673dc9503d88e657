/* The sprite table: the HUD (score and lives of each player, as sprites so
 * the background may scroll under them), players, crawlers and coins.
 *
 * Written through constant-address arrays indexed by a byte, which cc65
 * turns into single `sta abs,y` stores: a function call per sprite cost more
 * than a frame's worth of cycles. */
#include "game.h"

#define TILE_PLAYER 0x05  /* four tiles: top left, top right, bottom left, bottom right */
#define TILE_CRAWLER 0x09 /* two tiles: left, right */
#define TILE_COIN 0x0B
#define TILE_HEART 0x0C
#define FLIP_X 0x40
#define FLIP_Y 0x80

#define OAM_Y ((unsigned char *)(ADDR_OAM + 0))
#define OAM_TILE ((unsigned char *)(ADDR_OAM + 1))
#define OAM_ATTR ((unsigned char *)(ADDR_OAM + 2))
#define OAM_X ((unsigned char *)(ADDR_OAM + 3))

/* The next free entry (times 4); 0 once all 64 are used (entry 0 stays hidden).
 * `used` is where last frame's sprites ended: only those need hiding. */
static unsigned char slot, used;

/* Sprites show one line below their y. */
#define SPRITE(x, y, tile, attr)          \
    do {                                  \
        if (slot) {                       \
            OAM_Y[slot] = (y) - 1;        \
            OAM_TILE[slot] = (tile);      \
            OAM_ATTR[slot] = (attr);      \
            OAM_X[slot] = (x);            \
            slot += 4;                    \
        }                                 \
    } while (0)

static void hud(unsigned char n)
{
    register struct player *p = PLAYER(n);
    unsigned char i, y = 16 + 12 * n, x = n ? 160 : 16;
    if (p->state == PS_ABSENT)
        return;
    for (i = 0; i < 6; ++i, x += 8)
        SPRITE(x, y, '0' + p->score[i], n);
    SPRITE(x + 8, y, TILE_HEART, n);
    SPRITE(x + 16, y, '0' + (p->lives < 10 ? p->lives : 9), n);
}

static void draw_player(unsigned char n)
{
    register struct player *p = PLAYER(n);
    unsigned sx = p->x - camera_x - 8;
    int sy = p->y - 16;
    unsigned char attr = n, left = 0, right = 1, top = 0, bottom = 2, x, y;
    if (p->state != PS_ALIVE && p->state != PS_DYING)
        return;
    if (sx > 240 || sy < -8 || sy > 224)
        return;
    if (p->facing) {
        attr |= FLIP_X;
        left = 1;
        right = 0;
    }
    if (p->state == PS_DYING) {
        attr |= FLIP_Y;
        top = 2;
        bottom = 0;
    }
    x = (unsigned char)sx;
    y = (unsigned char)sy;
    if (sy >= 0) {
        SPRITE(x, y, TILE_PLAYER + top + left, attr);
        SPRITE(x + 8, y, TILE_PLAYER + top + right, attr);
    }
    if (sy < 216) {
        SPRITE(x, y + 8, TILE_PLAYER + bottom + left, attr);
        SPRITE(x + 8, y + 8, TILE_PLAYER + bottom + right, attr);
    }
}

static void draw_enemies(void)
{
    unsigned char i, x, attr;
    register struct enemy *e;
    unsigned sx;
    for (i = 0; i < enemy_count; ++i) {
        e = ENEMY(i);
        sx = e->x - camera_x - 8;
        if (e->state == ES_GONE || sx > 240)
            continue;
        x = (unsigned char)sx;
        attr = e->dir > 0 ? 2 | FLIP_X : 2;
        SPRITE(x, e->y - 8, TILE_CRAWLER + (e->dir > 0), attr);
        SPRITE(x + 8, e->y - 8, TILE_CRAWLER + (e->dir < 0), attr);
    }
}

static void draw_coins(void)
{
    unsigned char column = camera_x >> 4, last = column + 17, h;
    unsigned sx;
    for (; column != last; ++column) {
        if (!(ground[column] & GROUND_COIN))
            continue;
        sx = column * 16 + 4 - camera_x;
        h = ground[column] & 7;
        if (sx < 248)
            SPRITE((unsigned char)sx, 204 - 16 * h, TILE_COIN, 3);
    }
}

void draw_sprites(void)
{
    unsigned char i;
    slot = 4;
    if (game_mode != MODE_TITLE) {
        hud(0);
        hud(1);
        draw_player(0);
        draw_player(1);
        draw_enemies();
        draw_coins();
    }
    i = slot;
    while (slot && (slot < used || !used)) {
        OAM_Y[slot] = 0xFF;
        slot += 4;
    }
    used = i;
}
