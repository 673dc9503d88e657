/* The player (running, jumping, steps, walls, pits) and what it meets:
 * crawlers and coins. Speeds are in 1/16 pixel a frame. */
#include "player.h"
#include "ram.h"
#include "score.h"
#include "world.h"

#define ACCEL 2
#define MAX_SPEED 40      /* 2.5 pixels a frame */
#define JUMP_SPEED (-88)  /* rises about 48 pixels */
#define JUMP_CUT (-24)    /* a released jump button stops the rise here */
#define GRAVITY 5
#define MAX_FALL 96
#define HALF_WIDTH 5
#define STEP 8            /* walks up ground at most this much higher */
#define JUMP_BUTTONS (PAD_I | PAD_II)

void player_spawn(void) {
    PX = START_X;
    PY = 240 - 8 * 4;
    XS = YS = 0;
    VX = VY = 0;
    PSTATE = ALIVE;
    ON_GROUND = 1;
    FACING = 0;
    TIMER = 0;
}

void player_die(void) {
    PSTATE = DYING;
    TIMER = 0;
    VY = -64;
    --LIVES;
    ++DEATHS;
}

/* The highest ground under the player's feet: a column whose top is more than a
 * step above the feet is a wall beside the player, not ground under it. */
static int support(void) {
    int a = floor_at((int)PX - HALF_WIDTH), b = floor_at((int)PX + HALF_WIDTH);
    if (a < PY - STEP) a = NO_FLOOR;
    if (b < PY - STEP) b = NO_FLOOR;
    return a < b ? a : b;
}

static void run(void) {
    signed char vx = VX;
    int t, nx, front;
    unsigned char way = PAD & (PAD_LEFT | PAD_RIGHT);  /* both at once: neither, as on a real pad */
    if (way == PAD_RIGHT) {
        vx = vx + ACCEL > MAX_SPEED ? MAX_SPEED : vx + ACCEL;
        FACING = 0;
    } else if (way == PAD_LEFT) {
        vx = vx - ACCEL < -MAX_SPEED ? -MAX_SPEED : vx - ACCEL;
        FACING = 1;
    } else if (vx > 0) {
        vx = vx > ACCEL ? vx - ACCEL : 0;
    } else if (vx < 0) {
        vx = vx < -ACCEL ? vx + ACCEL : 0;
    }
    t = XS + vx;
    nx = (int)PX + (t >> 4);
    XS = t & 15;
    if (nx != (int)PX) {
        front = nx > (int)PX ? nx + HALF_WIDTH : nx - HALF_WIDTH;
        if (floor_at(front) < PY - STEP || nx < (int)CAMERA_X + 8 || nx > (int)LEVEL_WIDTH - 8) {
            vx = 0;   /* a wall, the screen's left edge or the level's end */
            XS = 0;
        } else {
            PX = nx;
        }
    }
    VX = vx;
}

static void fall(void) {
    int vy = VY, t, floor;
    if (ON_GROUND && (PAD_NEW & JUMP_BUTTONS)) {
        vy = JUMP_SPEED;
        ON_GROUND = 0;
    }
    if (vy < JUMP_CUT && !(PAD & JUMP_BUTTONS)) vy = JUMP_CUT;
    vy += GRAVITY;
    if (vy > MAX_FALL) vy = MAX_FALL;
    t = YS + vy;
    floor = support();
    if (vy >= 0 && PY + (t >> 4) >= floor) {
        PY = floor;   /* landing, or walking up a step */
        YS = 0;
        vy = 0;
        ON_GROUND = 1;
    } else {
        PY += t >> 4;
        YS = t & 15;
        ON_GROUND = 0;
    }
    VY = vy;
    if (PY > 256) player_die();
}

static void meet_crawlers(void) {
    struct enemy *e = ENEMY;
    unsigned char i;
    int dx, top;
    for (i = 0; i < ENEMY_COUNT; ++i, ++e) {
        if (!e->state) continue;
        dx = (int)e->x - (int)PX;
        if (dx < -12 || dx > 12) continue;
        top = (int)e->y - 11;
        if (PY < top || PY - 16 > (int)e->y) continue;
        if (!ON_GROUND) {
            e->state = 0;      /* a player in the air defeats it, and bounces off its top */
            if (VY > 0) VY = -56;
            add_score(2, 0x01);  /* 100 points */
        } else {
            player_die();
            return;
        }
    }
}

static void meet_coins(void) {
    struct coin *c = COIN;
    unsigned char i;
    int cx, cy;
    for (i = 0; i < COIN_COUNT; ++i, ++c) {
        if (c->taken) continue;
        cx = (int)(c->col << 3);
        cy = (int)c->row << 3;
        if ((int)PX + HALF_WIDTH < cx || (int)PX - HALF_WIDTH > cx + 7) continue;
        if (PY < cy || PY - 16 > cy + 7) continue;
        take_coin(i);
        ++COINS;
        add_score(3, 0x10);  /* 10 points */
    }
}

void crawlers_move(void) {
    struct enemy *e = ENEMY;
    unsigned char i;
    for (i = 0; i < ENEMY_COUNT; ++i, ++e) {
        if (e->state == 2) {
            if (--e->pause == 0) {
                e->state = 1;
                e->dir = -e->dir;
            }
        } else if (e->state == 1) {
            e->x += e->dir;
            if ((e->dir < 0 && e->x <= e->x0) || (e->dir > 0 && e->x >= e->x1)) {
                e->state = 2;
                e->pause = 8 + (RNG & 31);  /* a random wait at each end */
            }
        }
    }
}

void player_update(void) {
    if (PSTATE == DYING) {
        ++TIMER;
        if (TIMER > 20 && PY < 300) {
            VY = VY + 4 > MAX_FALL ? MAX_FALL : VY + 4;
            PY += VY >> 4;
        }
        return;
    }
    run();
    fall();
    if (PSTATE == ALIVE) meet_crawlers();
    if (PSTATE == ALIVE) meet_coins();
}
