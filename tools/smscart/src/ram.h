/*
 * Hopper's fixed RAM map: the game's whole state lives in one struct at the
 * start of the console's 8 KiB work RAM (0xC000-0xDFFF), so every value a tool
 * may want sits at a fixed address. The ADDR_* constants are the
 * documentation: games/Hopper-Sms/game.yaml and games/Hopper-GameGear/game.yaml
 * repeat them (tests/test_smscart.py checks that they agree), and the struct
 * is checked against them with _Static_assert, so the map cannot drift.
 *
 * Multi-byte values are little-endian, as the Z80 stores them; scores are BCD
 * (8 digits in 4 bytes, lowest pair first), as most Master System games keep
 * them. The stack grows down from 0xDFF0; the compiler's own data (none so
 * far) would go at 0xC400 (see the Makefile).
 */
#ifndef HOPPER_RAM_H
#define HOPPER_RAM_H

#include <stdint.h>

#define ADDR_LEVEL 0xC000       /* |u1 level select / current level, 0-3 (kept by the boot RAM clear) */
#define ADDR_GAME_MODE 0xC001   /* |u1 MODE_* below */
#define ADDR_LEVEL_DONE 0xC002  /* |u1 1 from reaching end_x until the next level starts */
#define ADDR_CONSOLE 0xC003     /* |u1 0 Master System build, 1 Game Gear build */
#define ADDR_FRAME 0xC004       /* <u2 main-loop frames since power-on */
#define ADDR_RNG 0xC006         /* <u2 random state */
#define ADDR_END_X 0xC008       /* <u2 the level's goal x */
#define ADDR_START_X 0xC00A     /* <u2 spawn x (player 2 spawns 12 pixels behind) */
#define ADDR_CAMERA_X 0xC00C    /* <u2 level x at the visible window's left edge */
#define ADDR_MODE_TIMER 0xC00E  /* <u2 frames left on the clear / game-over screen */
#define ADDR_VBLANKS 0xC010     /* |u1 frame interrupts taken (crt0.s increments it) */
#define ADDR_PAUSE 0xC011       /* |u1 set by the PAUSE button's NMI (crt0.s), cleared by the game */
#define ADDR_PAD1 0xC012        /* |u1 pad 1 held: PAD_* bits */
#define ADDR_PAD2 0xC013        /* |u1 pad 2 held */
#define ADDR_PAD1_NEW 0xC014    /* |u1 pad 1 pressed this frame */
#define ADDR_PAD2_NEW 0xC015    /* |u1 pad 2 pressed this frame */
#define ADDR_LEVEL_WIDTH 0xC016 /* <u2 the level's width in pixels */
#define ADDR_DRAWN 0xC018       /* <u2 columns of the level drawn into the name table so far */
#define ADDR_CRAWLER_COUNT 0xC01A /* |u1 crawlers in the level */
#define ADDR_COIN_COUNT 0xC01B  /* |u1 coins in the level */
#define ADDR_P1 0xC020          /* player 1's record, PLAYER_SIZE bytes */
#define ADDR_P2 0xC040          /* player 2's record */
#define ADDR_CRAWLERS 0xC060    /* MAX_CRAWLERS records of 8 bytes */
#define ADDR_COINS 0xC0A0       /* MAX_COINS records of 2 bytes: column, row | 0x80 once taken */
#define ADDR_GROUND 0xC100      /* 256 bytes: per 8-pixel column, the ground's height in tiles (0 = pit) */
#define ADDR_SAT 0xC200         /* 192 bytes: the sprite table, copied to VRAM every frame */

#define PLAYER_SIZE 0x20
#define MAX_CRAWLERS 8
#define MAX_COINS 32

/* game_mode */
#define MODE_TITLE 0
#define MODE_PLAY 1
#define MODE_CLEAR 2
#define MODE_GAMEOVER 3

/* player state */
#define PS_ALIVE 0
#define PS_DYING 1
#define PS_OUT 2
#define PS_ABSENT 3

/* pad bits (pad1, pad2, *_new) */
#define PAD_UP 0x01
#define PAD_DOWN 0x02
#define PAD_LEFT 0x04
#define PAD_RIGHT 0x08
#define PAD_B1 0x10
#define PAD_B2 0x20
#define PAD_START 0x80  /* Game Gear START, or the Master System's PAUSE on pad 1 */

typedef struct {
    uint16_t x;         /* +0x00 <u2 feet centre, level pixels */
    int16_t y;          /* +0x02 <i2 feet, screen pixels (the Master System's floor is 192 - 8 * height) */
    uint8_t xsub;       /* +0x04 x fraction, 1/256 pixel */
    uint8_t ysub;       /* +0x05 y fraction */
    int16_t vx;         /* +0x06 <i2 speed, 1/256 pixel a frame */
    int16_t vy;         /* +0x08 <i2 speed, positive is down */
    uint8_t state;      /* +0x0A PS_* */
    uint8_t lives;      /* +0x0B */
    uint8_t score[4];   /* +0x0C <d4 8 BCD digits, lowest pair first */
    uint8_t on_ground;  /* +0x10 */
    uint8_t facing;     /* +0x11 0 right, 1 left */
    uint8_t timer;      /* +0x12 frames into the death animation */
    uint8_t invuln;     /* +0x13 frames of safety left after a respawn */
    uint8_t deaths;     /* +0x14 lives lost so far */
    uint8_t coins;      /* +0x15 coins taken */
    uint8_t jump_held;  /* +0x16 the jump button is still held since the jump */
    uint8_t pad[9];
} Player;

typedef struct {
    uint16_t x;         /* +0 <u2 feet centre */
    uint16_t x0, x1;    /* +2, +4 <u2 patrol ends */
    uint8_t state;      /* +6 0 gone, 1 walking right, 2 walking left */
    uint8_t pause;      /* +7 frames left standing at a patrol end */
} Crawler;

typedef struct {
    uint8_t level, game_mode, level_done, console;
    uint16_t frame, rng, end_x, start_x, camera_x, mode_timer;
    uint8_t vblanks, pause, pad1, pad2, pad1_new, pad2_new;
    uint16_t level_width, drawn;
    uint8_t crawler_count, coin_count;
    uint8_t spare[4];
    Player p[2];
    Crawler crawlers[MAX_CRAWLERS];
    uint8_t coins[MAX_COINS][2];
    uint8_t spare2[32];
    uint8_t ground[256];
    uint8_t sat[192];
} Game;

extern volatile Game __at(ADDR_LEVEL) G;

#include <stddef.h>
#define OFF(f) offsetof(Game, f)
_Static_assert(OFF(frame) == ADDR_FRAME - ADDR_LEVEL, "frame");
_Static_assert(OFF(vblanks) == ADDR_VBLANKS - ADDR_LEVEL, "vblanks");
_Static_assert(OFF(pause) == ADDR_PAUSE - ADDR_LEVEL, "pause");
_Static_assert(OFF(level_width) == ADDR_LEVEL_WIDTH - ADDR_LEVEL, "level_width");
_Static_assert(OFF(crawler_count) == ADDR_CRAWLER_COUNT - ADDR_LEVEL, "crawler_count");
_Static_assert(OFF(p) == ADDR_P1 - ADDR_LEVEL, "p1");
_Static_assert(sizeof(Player) == PLAYER_SIZE, "player size");
_Static_assert(OFF(crawlers) == ADDR_CRAWLERS - ADDR_LEVEL, "crawlers");
_Static_assert(OFF(coins) == ADDR_COINS - ADDR_LEVEL, "coins");
_Static_assert(OFF(ground) == ADDR_GROUND - ADDR_LEVEL, "ground");
_Static_assert(OFF(sat) == ADDR_SAT - ADDR_LEVEL, "sat");

#endif
