/* Players, crawlers and coins: movement, collisions, score; the sprite table. */
#include "hopper.h"

#define ACCEL 0x28       /* 1/256 pixel a frame, each frame LEFT/RIGHT is held */
#define FRICTION 0x18
#define MAX_VX 0x300     /* 3 pixels a frame */
#define JUMP_VY 0x400    /* about 64 pixels high */
#define JUMP_RELEASE 0x180
#define GRAVITY 0x20
#define MAX_FALL 0x600
#define DEATH_FRAMES 90
#define RESPAWN_SAFE 60
#define PAD_JUMP (PAD_B1 | PAD_B2)

/* A 16-bit xorshift, stirred every frame by main() with the frame counter and pads. */
uint8_t rand8(void)
{
    uint16_t r = G.rng;
    r ^= r << 7;
    r ^= r >> 9;
    r ^= r << 8;
    G.rng = r ? r : 0x2A55;
    return (uint8_t)G.rng;
}

/* Add a BCD amount (up to 4 digits) to a player's 8-digit BCD score. */
void add_score(uint8_t i, uint16_t bcd)
{
    volatile uint8_t *s = G.p[i].score;
    uint8_t k, carry = 0, add, lo, hi;
    for (k = 0; k < 4; k++) {
        add = k == 0 ? bcd & 0xFF : k == 1 ? bcd >> 8 : 0;
        lo = (s[k] & 0x0F) + (add & 0x0F) + carry;
        carry = lo > 9;
        if (carry)
            lo -= 10;
        hi = (s[k] >> 4) + (add >> 4) + carry;
        carry = hi > 9;
        if (carry)
            hi -= 10;
        s[k] = (hi << 4) | lo;
    }
}

/* Place a player on solid ground at or right of x (never over a pit). */
static void place(volatile Player *p, uint16_t x)
{
    while (x + 16 < G.level_width && (!G.ground[(uint8_t)(x >> 3)] || !G.ground[(uint8_t)((x >> 3) + 1)]))
        x += 8;
    p->x = x;
    p->xsub = p->ysub = 0;
    p->y = ground_top(x);
    p->vx = p->vy = 0;
    p->on_ground = 1;
    p->facing = 0;
    p->jump_held = 0;
    p->state = PS_ALIVE;
}

void player_spawn(uint8_t i)
{
    uint16_t x = G.camera_x + 24 - 12 * i;
    place(&G.p[i], x > G.start_x - 12 * i ? x : G.start_x - 12 * i);
    G.p[i].invuln = RESPAWN_SAFE;
}

void players_spawn(void)
{
    uint8_t i;
    for (i = 0; i < PLAYERS; i++)
        if (G.p[i].state == PS_ALIVE || G.p[i].state == PS_DYING)
            place(&G.p[i], G.start_x - 12 * i);
}

static void lose_life(volatile Player *p)
{
    p->state = PS_DYING;
    p->lives--;
    p->deaths++;
    p->timer = 0;
    p->vx = 0;
    p->vy = -0x300;
}

/* The ground under a player's feet: the higher of the columns under its two
 * edges, so it stands while either foot is on a ledge. */
static int16_t support(uint16_t x)
{
    int16_t a = ground_top(x - 3), b = ground_top(x + 3);
    return a < b ? a : b;
}

/* Ground ahead higher than the feet is a wall, except one step (8 pixels)
 * for a player on foot, who walks up it. So a player who walks off into a
 * pit has fallen below the far side's top and cannot run across it. */
static void move_x(volatile Player *p)
{
    uint16_t sum = p->xsub + (uint8_t)(p->vx & 0xFF);
    uint16_t nx = p->x + (p->vx >> 8) + (sum >> 8);
    int16_t ahead = ground_top(p->vx > 0 ? nx + 3 : nx - 3);
    uint16_t left = G.camera_x + 6, right = G.camera_x + SCREEN_W - 6;

    if (nx < left || nx > right || ahead < p->y - (p->on_ground ? 8 : 0)) {
        p->vx = 0;  /* a screen edge or a wall */
        p->xsub = 0;
        if (p->x < left)
            p->x = left;
        return;
    }
    p->x = nx;
    p->xsub = sum & 0xFF;
    if (p->on_ground && ahead < p->y)
        p->y = ahead;  /* up a step */
}

static void move_y(volatile Player *p)
{
    int16_t top = support(p->x);
    uint16_t sum = p->ysub + (uint8_t)(p->vy & 0xFF);
    int16_t ny = p->y + (p->vy >> 8) + (sum >> 8);

    p->ysub = sum & 0xFF;
    if (p->vy >= 0 && ny >= top && p->y <= top) {
        p->y = top;  /* standing, or landed from above */
        p->vy = 0;
        p->ysub = 0;
        p->on_ground = 1;
        return;
    }
    p->y = ny;
    p->on_ground = 0;
}

static void take_coins(uint8_t i)
{
    volatile Player *p = &G.p[i];
    uint8_t k, col, row;
    int16_t cy;
    for (k = 0; k < G.coin_count; k++) {
        col = G.coins[k][0];
        row = G.coins[k][1];
        if (row & 0x80)
            continue;
        cy = (row << 3) + 4;
        if (p->x + 4 > ((uint16_t)col << 3) && p->x < ((uint16_t)col << 3) + 12 && p->y > cy && p->y < cy + 20) {
            G.coins[k][1] = row | 0x80;
            vdp_put_tile(col, row, T_SKY);
            p->coins++;
            add_score(i, 0x10);
        }
    }
}

static void player_update(uint8_t i)
{
    volatile Player *p = &G.p[i];
    uint8_t held = i ? G.pad2 : G.pad1, pressed = i ? G.pad2_new : G.pad1_new;

    if (p->state == PS_DYING) {
        p->vy += GRAVITY;
        p->y += p->vy >> 8;
        if (++p->timer >= DEATH_FRAMES) {
            if (p->lives)
                player_spawn(i);
            else
                p->state = PS_OUT;
        }
        return;
    }
    if (p->state != PS_ALIVE)
        return;
    if (p->invuln)
        p->invuln--;

    /* LEFT and RIGHT together cancel out (the pad's rocker cannot press both). */
    if ((held & (PAD_LEFT | PAD_RIGHT)) == PAD_RIGHT) {
        p->vx = p->vx + ACCEL > MAX_VX ? MAX_VX : p->vx + ACCEL;
        p->facing = 0;
    } else if ((held & (PAD_LEFT | PAD_RIGHT)) == PAD_LEFT) {
        p->vx = p->vx - ACCEL < -MAX_VX ? -MAX_VX : p->vx - ACCEL;
        p->facing = 1;
    } else if (p->vx > FRICTION) {
        p->vx -= FRICTION;
    } else if (p->vx < -FRICTION) {
        p->vx += FRICTION;
    } else {
        p->vx = 0;
    }
    if (p->on_ground && (pressed & PAD_JUMP)) {
        p->vy = -JUMP_VY;
        p->on_ground = 0;
        p->jump_held = 1;
    }
    if (!(held & PAD_JUMP))
        p->jump_held = 0;
    if (!p->on_ground) {
        if (!p->jump_held && p->vy < -JUMP_RELEASE)
            p->vy = -JUMP_RELEASE;
        p->vy = p->vy + GRAVITY > MAX_FALL ? MAX_FALL : p->vy + GRAVITY;
    }
    move_x(p);
    move_y(p);
    if (p->y > SCREEN_BOTTOM + 16) {
        lose_life(p);  /* fell into a pit */
        return;
    }
    take_coins(i);
    if (p->x >= G.end_x && !G.level_done) {
        G.level_done = 1;
        add_score(i, 0x1000);
    }
}

void players_update(void)
{
    uint8_t i;
    for (i = 0; i < PLAYERS; i++)
        player_update(i);
}

/* Crawlers patrol between their ends at half a pixel a frame, standing a
 * random time at each end. A player coming down on one defeats it (100
 * points) and bounces; any other touch costs the player a life. */
void crawlers_update(void)
{
    uint8_t k, i;
    for (k = 0; k < G.crawler_count; k++) {
        volatile Crawler *c = &G.crawlers[k];
        if (!c->state)
            continue;
        if (c->pause) {
            c->pause--;
        } else if (G.frame & 1) {
            if (c->state == 1 && ++c->x >= c->x1) {
                c->state = 2;
                c->pause = rand8() & 63;
            } else if (c->state == 2 && --c->x <= c->x0) {
                c->state = 1;
                c->pause = rand8() & 63;
            }
        }
        for (i = 0; i < PLAYERS; i++) {
            volatile Player *p = &G.p[i];
            int16_t cy = ground_top(c->x), dx = (int16_t)(p->x - c->x);
            if (p->state != PS_ALIVE || dx < -7 || dx > 7 || p->y < cy - 12 || p->y > cy + 8)
                continue;
            if (p->vy > 0 && p->y < cy - 3) {
                c->state = 0;
                p->vy = -0x300;
                add_score(i, 0x100);
                break;
            }
            if (!p->invuln)
                lose_life(p);
        }
    }
}

/* Sprite table: one sprite at screen (x, y) (the VDP draws a sprite a line
 * below its y); returns the next slot. */
static uint8_t sprite(uint8_t n, int16_t x, int16_t y, uint8_t tile)
{
    if (n >= 63 || x < 0 || x > 248 || y < SCREEN_TOP - 8 || y >= SCREEN_BOTTOM)
        return n;
    G.sat[n] = (uint8_t)(y - 1);
    G.sat[64 + 2 * n] = (uint8_t)x;
    G.sat[65 + 2 * n] = tile;
    return n + 1;
}

static int16_t screen_x(uint16_t x)
{
    return (int16_t)(x - G.camera_x) + SCREEN_LEFT - 4;
}

void sprites_build(void)
{
    uint8_t n = 0, i, k, d;
    for (i = 0; i < PLAYERS; i++) {
        volatile Player *p = &G.p[i];
        if (p->state == PS_ALIVE || p->state == PS_DYING) {
            if (p->invuln & 4)
                continue;  /* blink while safe after a respawn */
            n = sprite(n, screen_x(p->x), p->y - 16, T_P1 + 2 * i);
            n = sprite(n, screen_x(p->x), p->y - 8, T_P1 + 2 * i + 1);
        }
    }
    for (k = 0; k < G.crawler_count; k++) {
        volatile Crawler *c = &G.crawlers[k];
        if (c->state)
            n = sprite(n, screen_x(c->x), ground_top(c->x) - 8, T_CRAWLER + ((c->x >> 2) & 1));
    }
    n = sprite(n, screen_x(G.end_x) + 4, ground_top(G.end_x) - 8, T_FLAG);
    /* HUD: each joined player's 6 lowest score digits and lives */
    for (i = 0; i < PLAYERS; i++) {
        volatile Player *p = &G.p[i];
        if (p->state == PS_ABSENT)
            continue;
        for (d = 0; d < 6; d++) {
            k = p->score[2 - (d >> 1)];
            n = sprite(n, SCREEN_LEFT + 8 + 8 * d, SCREEN_TOP + 4 + 10 * i, '0' + ((d & 1) ? k & 15 : k >> 4));
        }
        n = sprite(n, SCREEN_LEFT + 64, SCREEN_TOP + 4 + 10 * i, T_P1 + 2 * i);
        n = sprite(n, SCREEN_LEFT + 72, SCREEN_TOP + 4 + 10 * i, '0' + p->lives);
    }
    G.sat[n] = 0xD0;
}
