/* Crawlers: they patrol a flat run of ground, pausing a random time at each
 * end; landing on one defeats it (100 points), touching it otherwise costs a
 * life. */
#include "game.h"

#define STOMP_BOUNCE 40

static void touch(struct enemy *e)
{
    unsigned char n;
    register struct player *p;
    for (n = 0; n < 2; ++n) {
        p = PLAYER(n);
        if (p->state != PS_ALIVE)
            continue;
        /* Overlap: |dx| < 12, and the player's 14-pixel body across the
         * crawler's 8 (unsigned differences: one compare a side). */
        if ((unsigned)(p->x - e->x + 11) >= 23 || (unsigned)(p->y - e->y + 7) >= 21)
            continue;
        if (p->vy > 0 && p->y <= (int)e->y - 4) {
            e->state = ES_GONE;
            p->vy = -STOMP_BOUNCE;
            p->jump_held = 0;
            add_score(n, 3, 1);
            return;
        }
        player_die(n);
    }
}

void enemies_update(void)
{
    unsigned char i;
    register struct enemy *e;
    for (i = 0; i < enemy_count; ++i) {
        e = ENEMY(i);
        if (e->state == ES_WALK) {
            if (frame_lo & 1)
                e->x += e->dir;
            if ((e->dir < 0 && e->x <= e->x0) || (e->dir > 0 && e->x >= e->x1)) {
                e->state = ES_PAUSE;
                e->pause = rnd() & 63;
            }
        } else if (e->state == ES_PAUSE) {
            if (e->pause)
                --e->pause;
            else {
                e->dir = -e->dir;
                e->state = ES_WALK;
            }
        }
        /* Players are always on screen: only crawlers near it can touch one. */
        if (e->state != ES_GONE && e->x + 16 > camera_x && e->x < camera_x + 272)
            touch(e);
    }
}
