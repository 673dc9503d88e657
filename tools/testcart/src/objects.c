/*
 * Rings (cells of plane A, listed in RAM at ADDR_RINGS) and crawlers (sprites,
 * ADDR_ENEMIES).  Crawlers walk to the ends of their patrol and stand there
 * for a random time, so their position when a player arrives depends on
 * the frame the act began and on the player's speed.
 */
#include "objects.h"
#include "player.h"
#include "util.h"
#include "world.h"

#define ENEMY_HALF_W 7
#define ENEMY_H 12

void enemies_update(void)
{
    u16 i;
    for (i = 0; i < RAM.enemy_count; i++) {
        struct enemy *e = &RAM.enemies[i];
        if (e->state == 2) { /* paused at an end */
            if (--e->pause == 0) {
                e->state = 1;
                e->dir = -e->dir;
            }
        } else if (e->state == 1) {
            e->x += e->dir;
            if ((e->dir < 0 && e->x <= e->x0) || (e->dir > 0 && e->x >= e->x1)) {
                e->state = 2;
                e->pause = 8 + (rng_next() & 63);
            }
        }
    }
}

static void touch_rings(struct player *p)
{
    u16 i;
    for (i = 0; i < RAM.ring_count; i++) {
        struct ring *r = &RAM.rings[i];
        s16 dx = (s16)(r->col * 8 + 4) - p->x;
        s16 ry = r->row * 8 + 4;
        if (r->taken || dx < -9 || dx > 9)
            continue;
        if (ry > p->y - PLAYER_H - 4 && ry < p->y + 4) {
            r->taken = 1;
            if (p->rings < 999)
                p->rings++;
            score_add(p->score, 0x0010);
            world_redraw(r->col);
        }
    }
}

/* A player in the air (rolled into a ball) defeats a crawler; on foot it
 * gets hurt.  Landing on one bounces the player back up. */
static void touch_enemies(struct player *p)
{
    u16 i;
    for (i = 0; i < RAM.enemy_count; i++) {
        struct enemy *e = &RAM.enemies[i];
        s16 dx = e->x - p->x;
        if (!e->state || dx <= -(ENEMY_HALF_W + PLAYER_HALF_W) ||
            dx >= ENEMY_HALF_W + PLAYER_HALF_W)
            continue;
        if (p->y <= e->y - ENEMY_H || p->y - PLAYER_H >= e->y)
            continue;
        if (!p->on_ground) {
            e->state = 0;
            score_add(p->score, 0x0100);
            if (p->vy > 0)
                p->vy = p->jump_held ? -0x500 : -0x300;
        } else {
            player_hurt(p);
        }
    }
}

void objects_touch(struct player *p)
{
    if (p->state != PS_ALIVE)
        return;
    touch_rings(p);
    touch_enemies(p);
}
