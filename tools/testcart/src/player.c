/*
 * Player physics, Sonic-like in miniature.  Positions are pixels plus a
 * 1/256 fraction; speeds are in 1/256 pixel per frame.  The feet are at
 * (x, y); the terrain is the column height map of world.c.
 */
#include "player.h"
#include "util.h"
#include "world.h"

#define ACCEL 0x0C        /* ground acceleration per frame */
#define AIR_ACCEL 0x18
#define DECEL 0x60        /* braking when pushing against the motion */
#define FRICTION 0x0C
#define TOP_SPEED 0x300   /* 3 px / frame */
#define JUMP_SPEED 0x540  /* apex about 70 px up, 56 frames in the air */
#define JUMP_RELEASE 0x300 /* rising speed kept when jump is let go early */
#define GRAVITY 0x30
#define MAX_FALL 0x800
#define STEP 8            /* on foot, rises of up to 8 px are walked up */
#define DEATH_FRAMES 120  /* death animation before respawning */
#define HURT_INVULN 120
#define SPAWN_INVULN 60

void player_spawn(struct player *p, u16 index)
{
    p->x = RAM.start_x - 20 * index;
    p->y = world_ground_y(p->x);
    p->xsub = p->ysub = 0;
    p->vx = p->vy = 0;
    p->on_ground = 1;
    p->facing = 0;
    p->rings = 0;
    p->timer = 0;
    p->invuln = SPAWN_INVULN;
    p->jump_held = 0;
    p->state = PS_ALIVE;
}

void player_die(struct player *p)
{
    if (p->state != PS_ALIVE)
        return;
    p->state = PS_DYING;
    if (p->lives)
        p->lives--;
    p->deaths++;
    p->vx = 0;
    p->vy = -0x600; /* hop up, then fall off the screen */
    p->on_ground = 0;
    p->timer = 0;
}

/* A hit from a crawler or spikes: rings act as a shield, like Sonic's. */
void player_hurt(struct player *p)
{
    if (p->state != PS_ALIVE || p->invuln)
        return;
    if (p->rings == 0) {
        player_die(p);
        return;
    }
    p->rings = 0;
    p->invuln = HURT_INVULN;
    p->vy = -0x400;
    p->vx = p->facing ? 0x200 : -0x200; /* knocked back */
    p->on_ground = 0;
}

static void run(struct player *p, u8 held)
{
    s16 accel = p->on_ground ? ACCEL : AIR_ACCEL;
    if (held & PAD_RIGHT) {
        p->facing = 0;
        if (p->vx < 0)
            p->vx += DECEL;
        else if (p->vx < TOP_SPEED)
            p->vx = p->vx + accel > TOP_SPEED ? TOP_SPEED : p->vx + accel;
    } else if (held & PAD_LEFT) {
        p->facing = 1;
        if (p->vx > 0)
            p->vx -= DECEL;
        else if (p->vx > -TOP_SPEED)
            p->vx = p->vx - accel < -TOP_SPEED ? -TOP_SPEED : p->vx - accel;
    } else if (p->on_ground) {
        if (p->vx > FRICTION)
            p->vx -= FRICTION;
        else if (p->vx < -FRICTION)
            p->vx += FRICTION;
        else
            p->vx = 0;
    }
}

/* Move along x, stopping at walls and at the level's ends.  On the ground a
 * rise of up to STEP pixels is a step; in the air any floor above the feet
 * is a wall, so a player who drops into a pit cannot climb out of it. */
static void move_x(struct player *p)
{
    s32 pos = ((s32)p->x << 8) + p->xsub + p->vx;
    s16 nx = (s16)(pos >> 8);
    s16 limit = p->on_ground ? p->y - STEP : p->y;
    if (p->vx > 0) {
        s16 edge = nx + PLAYER_HALF_W;
        if (world_ground_y(edge) < limit) {
            nx = (edge & ~7) - PLAYER_HALF_W - 1;
            pos = (s32)nx << 8;
            p->vx = 0;
        }
    } else if (p->vx < 0) {
        s16 edge = nx - PLAYER_HALF_W;
        if (world_ground_y(edge) < limit) {
            nx = (edge | 7) + 1 + PLAYER_HALF_W;
            pos = (s32)nx << 8;
            p->vx = 0;
        }
    }
    if (nx < 8) {
        nx = 8;
        pos = (s32)nx << 8;
        p->vx = 0;
    } else if (nx > (s16)RAM.level_width - 8) {
        nx = RAM.level_width - 8;
        pos = (s32)nx << 8;
        p->vx = 0;
    }
    p->x = nx;
    p->xsub = (u8)pos;
}

/* The floor under the feet: the higher of two sensors at the hit box's
 * sides, so the player only falls once fully over a pit. */
static s16 floor_y(s16 x)
{
    s16 a = world_ground_y(x - PLAYER_HALF_W + 1);
    s16 b = world_ground_y(x + PLAYER_HALF_W - 1);
    return a < b ? a : b;
}

static void move_y(struct player *p)
{
    s16 gnd = floor_y(p->x);
    if (p->on_ground) {
        if (gnd > p->y) {
            p->on_ground = 0; /* walked off an edge */
        } else {
            p->y = gnd; /* walk up a step */
            p->vy = 0;
        }
    }
    if (!p->on_ground) {
        s16 old = p->y;
        s32 pos = ((s32)p->y << 8) + p->ysub + p->vy;
        p->y = (s16)(pos >> 8);
        p->ysub = (u8)pos;
        /* Land only when the feet cross the floor's top this frame. */
        if (p->vy >= 0 && gnd != NO_GROUND && p->y >= gnd && old <= gnd) {
            p->y = gnd;
            p->ysub = 0;
            p->vy = 0;
            p->on_ground = 1;
        }
    }
}

/* Spikes fill the cell above their column's floor. */
static int on_spikes(struct player *p)
{
    s16 x;
    for (x = p->x - PLAYER_HALF_W + 1; x <= p->x + PLAYER_HALF_W - 1; x += 2 * PLAYER_HALF_W - 2)
        if ((world_ground(x) & GROUND_SPIKES) && p->y >= world_ground_y(x) - 8)
            return 1;
    return 0;
}

static void dying(struct player *p, u16 index)
{
    p->vy += GRAVITY;
    p->y += p->vy >> 8;
    if (++p->timer < DEATH_FRAMES)
        return;
    if (p->lives)
        player_spawn(p, index);
    else
        p->state = PS_OUT;
}

void player_update(struct player *p, u16 index, u8 held, u8 pressed)
{
    if (p->state == PS_DYING) {
        dying(p, index);
        return;
    }
    if (p->state != PS_ALIVE)
        return;
    if (p->invuln)
        p->invuln--;
    run(p, held);
    if (p->on_ground && (pressed & PAD_JUMP)) {
        p->vy = -JUMP_SPEED;
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
    p->anim += (u8)((p->vx < 0 ? -p->vx : p->vx) >> 5);
    if (p->y > SCREEN_H + 32)
        player_die(p); /* fell into a pit */
    else if (on_spikes(p))
        player_hurt(p);
}
