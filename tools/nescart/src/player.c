/* Player physics: running, jumping, walls and pits, coins, death and respawn.
 * Speeds are in 1/16 pixel a frame. */
#include "game.h"

#define RUN_MAX 40       /* 2.5 px a frame */
#define RUN_ACCEL 2
#define JUMP_SPEED 72    /* apex about 40 px up, 36 frames in the air */
#define JUMP_RELEASE 24  /* rising speed kept when jump is let go early */
#define GRAVITY 4
#define FALL_MAX 96
#define DEATH_FRAMES 60
#define FALL_DEATH_Y 248

unsigned char leader(void)
{
    return PLAYER(0)->state == PS_OUT ? 1 : 0;
}

void player_spawn(unsigned char n, unsigned x, int y)
{
    struct player *p = PLAYER(n);
    p->x = x;
    p->y = y;
    p->xsub = p->ysub = 0;
    p->vx = p->vy = 0;
    p->state = PS_ALIVE;
    p->on_ground = 0;
    p->facing = 0;
    p->timer = 0;
    p->jump_held = 0;
}

/* Add `amount` at decimal digit `digit` (0 = most significant) of a score. */
void add_score(unsigned char n, unsigned char digit, unsigned char amount)
{
    unsigned char *score = PLAYER(n)->score;
    for (;;) {
        score[digit] += amount;
        if (score[digit] < 10)
            return;
        score[digit] -= 10;
        if (digit == 0) {
            score[0] = 9; /* the counter stops at 999990 */
            return;
        }
        --digit;
        amount = 1;
    }
}

void player_die(unsigned char n)
{
    struct player *p = PLAYER(n);
    p->state = PS_DYING;
    --p->lives;
    ++p->deaths;
    p->timer = 0;
    p->vx = 0;
    p->vy = -48;
    p->on_ground = 0;
}

/* Move `pos` (pixels) and `sub` (1/16) by `speed`. */
static int step(int pos, unsigned char *sub, signed char speed)
{
    int s = *sub + speed;
    while (s >= 16) {
        s -= 16;
        ++pos;
    }
    while (s < 0) {
        s += 16;
        --pos;
    }
    *sub = (unsigned char)s;
    return pos;
}

static void end_of_death(unsigned char n)
{
    struct player *p = PLAYER(n), *lead;
    unsigned char other = n ^ 1;
    if (p->lives == 0) {
        p->state = PS_OUT;
        return;
    }
    if (n == leader()) {
        /* The leader restarts the stage, and brings the other player along. */
        camera_x = 0;
        player_spawn(n, start_x, 0);
        if (PLAYER(other)->state == PS_ALIVE)
            player_spawn(other, n ? start_x : start_x - 16, 0);
        redraw();
    } else {
        lead = PLAYER(leader());
        player_spawn(n, lead->x, lead->y - 24);
    }
}

static void take_coin(unsigned char n, struct player *p)
{
    unsigned char column = p->x >> 4;
    int coin_y;
    if (!(ground[column] & GROUND_COIN))
        return;
    coin_y = ground_top(p->x) - 20;   /* the coin's top; it is 8 pixels tall */
    if (p->y > coin_y && p->y - 14 < coin_y + 8) {
        ground[column] &= ~GROUND_COIN;
        ++p->coins;
        add_score(n, 4, 1);
    }
}

static void run(struct player *p, unsigned char held)
{
    int x;
    /* A pad's rocker cannot press both ways at once; a tool can, and then
     * neither counts. */
    if ((held & (PAD_LEFT | PAD_RIGHT)) == (PAD_LEFT | PAD_RIGHT))
        held &= ~(PAD_LEFT | PAD_RIGHT);
    if (held & PAD_RIGHT) {
        if (p->vx < RUN_MAX)
            p->vx += RUN_ACCEL;
        p->facing = 0;
    } else if (held & PAD_LEFT) {
        if (p->vx > -RUN_MAX)
            p->vx -= RUN_ACCEL;
        p->facing = 1;
    } else if (p->vx > 0) {
        p->vx -= RUN_ACCEL;
    } else if (p->vx < 0) {
        p->vx += RUN_ACCEL;
    }
    x = step(p->x, &p->xsub, p->vx);
    /* Stay on screen: the camera never scrolls back. */
    if (x < (int)camera_x + 8)
        x = camera_x + 8;
    if (x > (int)camera_x + 248)
        x = camera_x + 248;
    if (x > (int)level_width - 8)
        x = level_width - 8;
    /* Ground higher than the feet at the leading edge is a wall. */
    if (x != (int)p->x && ground_top(x > (int)p->x ? x + 5 : x - 6) < p->y) {
        p->vx = 0;
        p->xsub = 0;
        return;
    }
    p->x = x;
}

static void fall(struct player *p, unsigned char held, unsigned char pressed)
{
    int y, top;
    if (p->on_ground && (pressed & PAD_JUMP)) {
        p->vy = -JUMP_SPEED;
        p->on_ground = 0;
        p->jump_held = 1;
    }
    if (!(held & PAD_JUMP))
        p->jump_held = 0;
    if (!p->jump_held && p->vy < -JUMP_RELEASE)
        p->vy = -JUMP_RELEASE;
    if (p->vy < FALL_MAX)
        p->vy += GRAVITY;
    y = step(p->y, &p->ysub, p->vy);
    top = ground_top(p->x);
    p->on_ground = 0;
    if (p->vy >= 0 && p->y <= top && y >= top) {
        y = top;
        p->vy = 0;
        p->ysub = 0;
        p->on_ground = 1;
    }
    p->y = y;
}

void player_update(unsigned char n, unsigned char held, unsigned char pressed)
{
    register struct player *p = PLAYER(n);
    switch (p->state) {
    case PS_ALIVE:
        run(p, held);
        fall(p, held, pressed);
        take_coin(n, p);
        if (p->y > FALL_DEATH_Y)
            player_die(n);
        break;
    case PS_DYING:
        if (p->vy < FALL_MAX)
            p->vy += GRAVITY;
        if (p->y < 300)
            p->y = step(p->y, &p->ysub, p->vy);
        if (++p->timer >= DEATH_FRAMES)
            end_of_death(n);
        break;
    case PS_ABSENT:
        /* Player 2 joins beside the leader with any button on pad 2. */
        if (n == 1 && pressed) {
            p->lives = 3;
            player_spawn(1, PLAYER(0)->x, PLAYER(0)->y - 24);
            players = 2;
        }
        break;
    }
}
