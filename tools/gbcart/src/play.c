/*
 * Playing: the player's physics, walkers, coins, the score and the goal.
 *
 * Positions are level pixels with a 1/256 fraction; speeds are 1/256 pixel a
 * frame.  The ground map gives each 8-pixel column a floor height (0 = a pit):
 * the player walks up one-tile steps, taller ground is a wall to jump, and a
 * pit is bottomless.
 */
#include "ram.h"
#include "game.h"

#define RUN_ACCEL 0x20
#define RUN_MAX 0x200   /* 2 pixels a frame */
#define FRICTION 0x18
#define JUMP_SPEED 0x3C0
#define JUMP_CUT 0x100  /* releasing the button early caps the rise at this speed */
#define GRAVITY 0x24
#define FALL_MAX 0x500
#define FELL_Y 160      /* below the screen: a life lost */
#define DEATH_FRAMES 60


/* The floor's top at a level x; 255 over a pit or outside the level. */
static uint8_t floor_at(int16_t x) {
    uint8_t h;
    if (x < 0 || x >= (int16_t)level_width)
        return 255;
    h = ground[(uint16_t)x >> 3] & 0x0F;
    return h ? (uint8_t)(136 - 8 * h) : 255;
}

/* Add a BCD byte to the score's byte `byte` (0 = the two lowest digits), with carry. */
void add_score(uint8_t byte, uint8_t bcd) {
    for (; byte < 4; ++byte) {
        uint8_t s = player.score[byte];
        uint8_t lo = (s & 15) + (bcd & 15);
        uint8_t hi = (s >> 4) + (bcd >> 4);
        if (lo > 9) {
            lo -= 10;
            ++hi;
        }
        if (hi > 9) {
            player.score[byte] = (uint8_t)(((hi - 10) << 4) | lo);
            bcd = 1;
        } else {
            player.score[byte] = (uint8_t)((hi << 4) | lo);
            break;
        }
    }
    hud_show_score();
}

void player_spawn(void) {
    player.x = start_x;
    player.xsub = 0;
    player.y = floor_at(start_x);
    player.ysub = 0;
    player.vx = 0;
    player.vy = 0;
    player.state = PS_ALIVE;
    player.on_ground = 1;
    player.facing = 0;
    player.timer = 0;
    player.jump_held = 0;
}

static void lose_life(void) {
    player.state = PS_DYING;
    player.timer = 0;
    player.vx = 0;
    if (player.lives)
        --player.lives;
    ++player.deaths;
    hud_show_score();
}

/* Add a speed to a position with its fraction. */
static int16_t move(int16_t pos, uint8_t *sub, int16_t speed) {
    uint16_t s = (uint16_t)*sub + (uint8_t)speed;
    *sub = (uint8_t)s;
    return pos + (speed >> 8) + (int16_t)(s >> 8);
}

static void run_and_jump(void) {
    uint8_t held = pad;
    int16_t vx = player.vx;
    int16_t x, y;
    uint8_t floor;
    /* A real d-pad cannot press left and right at once: both count as neither. */
    if ((held & (PAD_LEFT | PAD_RIGHT)) == (PAD_LEFT | PAD_RIGHT))
        held &= (uint8_t)~(PAD_LEFT | PAD_RIGHT);
    if (held & PAD_RIGHT) {
        vx += vx < 0 ? 2 * RUN_ACCEL : RUN_ACCEL;
        if (vx > RUN_MAX)
            vx = RUN_MAX;
        player.facing = 0;
    } else if (held & PAD_LEFT) {
        vx -= vx > 0 ? 2 * RUN_ACCEL : RUN_ACCEL;
        if (vx < -RUN_MAX)
            vx = -RUN_MAX;
        player.facing = 1;
    } else if (vx > FRICTION) {
        vx -= FRICTION;
    } else if (vx < -FRICTION) {
        vx += FRICTION;
    } else {
        vx = 0;
    }
    /* A and B both jump. */
    if (player.on_ground && (pad_new & (PAD_A | PAD_B))) {
        player.vy = -JUMP_SPEED;
        player.on_ground = 0;
        player.jump_held = 1;
    }
    if (player.jump_held && !(held & (PAD_A | PAD_B))) {
        player.jump_held = 0;
        if (player.vy < -JUMP_CUT)
            player.vy = -JUMP_CUT;
    }

    /* Across: a column whose floor is more than a step above the feet is a wall. */
    x = move(player.x, &player.xsub, vx);
    if (vx) {
        floor = floor_at(vx > 0 ? x + 3 : x - 4);
        if (floor != 255 && (int16_t)floor < player.y - 8) {
            x = player.x;
            player.xsub = 0;
            vx = 0;
        } else if (player.on_ground && floor != 255 && (int16_t)floor < player.y) {
            player.y = floor; /* a step up */
        }
    }
    if (x < (int16_t)camera_x + 4)
        x = camera_x + 4;
    if (x > (int16_t)level_width - 4)
        x = level_width - 4;
    player.x = x;
    player.vx = vx;

    /* Down: gravity, then land on the floor under the feet' centre (feet up
     * to a step below its top, as when a jump only just reaches a ledge). */
    if (player.vy < FALL_MAX)
        player.vy += GRAVITY;
    y = move(player.y, &player.ysub, player.vy);
    floor = floor_at(x);
    player.on_ground = 0;
    if (player.vy >= 0 && floor != 255 && y >= floor && player.y <= (int16_t)floor + 8) {
        y = floor;
        player.ysub = 0;
        player.vy = 0;
        player.on_ground = 1;
    }
    player.y = y;
    if (y >= FELL_Y)
        lose_life();
}

static void take_coin(void) {
    uint8_t column = (uint16_t)player.x >> 3;
    uint8_t g = ground[column];
    uint8_t floor;
    if (!(g & 0x80))
        return;
    floor = 136 - 8 * (g & 0x0F);
    if (player.y > floor - 24 && player.y < floor) {
        clear_coin_tile(column);
        ground[column] = g & 0x7F;
        ++player.coins;
        add_score(0, 0x10);
    }
}

static void walkers(void) {
    uint8_t i;
    for (i = 0; i < ENEMY_MAX; ++i) {
        Enemy *e = &enemies[i];
        int16_t dx;
        uint8_t floor;
        if (e->state == 2) {
            /* Paused at an end of the patrol for a random time. */
            if (--e->info & 0x7F)
                continue;
            e->state = 1;
        } else if (e->state == 1) {
            if (e->info & 0x80) {
                if (--e->x <= e->x0) {
                    e->state = 2;
                    e->info = 8 + (rng & 31); /* then walk right */
                }
            } else if (++e->x >= e->x1) {
                e->state = 2;
                e->info = 0x80 | (8 + (rng & 31));
            }
        } else {
            continue;
        }
        if (player.state != PS_ALIVE)
            continue;
        dx = player.x - (int16_t)e->x;
        floor = 136 - 8 * (ground[e->x >> 3] & 0x0F);
        if (dx > -7 && dx < 7 && player.y > floor - 8 && player.y - 14 < floor) {
            if (player.vy > 0 && player.y < floor - 3) {
                e->state = 0; /* stomped */
                player.vy = -0x300;
                player.jump_held = 0;
                add_score(1, 0x01);
            } else {
                lose_life();
            }
        }
    }
}

static void follow_camera(void) {
    int16_t target = player.x - 64;
    uint16_t most = level_width - 160;
    uint8_t before = (uint8_t)(camera_x >> 3);
    if (target > (int16_t)camera_x) {
        camera_x = (uint16_t)target > most ? most : (uint16_t)target;
        if ((uint8_t)(camera_x >> 3) != before)
            prepare_column((uint8_t)((camera_x >> 3) + 21));
    }
}

/* One frame of play; returns with game_mode changed when the level ends. */
void play_step(void) {
    if (player.state == PS_ALIVE) {
        run_and_jump();
        take_coin();
    }
    walkers();
    if (player.state == PS_ALIVE) {
        follow_camera();
        if (player.x >= (int16_t)end_x) {
            level_done = 1;
            add_score(1, 0x10);
            game_mode = MODE_CLEAR;
            mode_timer = 120;
            hud_message("   LEVEL CLEAR!");
        }
    } else if (player.state == PS_DYING && ++player.timer >= DEATH_FRAMES) {
        if (player.lives) {
            start_level(); /* the level starts again, coins and walkers too */
        } else {
            player.state = PS_OUT;
            game_mode = MODE_GAMEOVER;
            mode_timer = 180;
            hud_message("     GAME OVER");
        }
    }
}
