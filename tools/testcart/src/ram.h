/*
 * Dasher's fixed RAM map.
 *
 * Everything a tool may want to read or write lives at a fixed address in the
 * first 4 KiB of 68000 work RAM (0xFF0000-0xFF0FFF); the linker places the
 * compiler's own .data/.bss above 0xFF1000.  The ADDR_* constants are the
 * documentation: games/Dasher-Genesis/game.yaml repeats them (a test checks
 * that the two agree) and the C structs below are checked against them with
 * _Static_assert, so the map cannot drift silently.
 *
 * Multi-byte values are big-endian, as the 68000 stores them.
 * This header is also included by boot/crt0.S (only the #defines are seen).
 */
#ifndef DASHER_RAM_H
#define DASHER_RAM_H

#define RAM_BASE 0xFF0000

/* --- Level select: kept by the boot-time RAM clear (see crt0.S) ----------- */
#define ADDR_ZONE 0xFF0000       /* |u1 zone 0-2: at the title, the zone START begins */
#define ADDR_ACT 0xFF0001        /* |u1 act 0-1: likewise */
/* --- Game state ------------------------------------------------------------ */
#define ADDR_GAME_MODE 0xFF0002  /* |u1 MODE_* below */
#define ADDR_LEVEL_DONE 0xFF0003 /* |u1 1 from reaching end_x until the next act */
#define ADDR_FRAME 0xFF0004      /* >u4 main-loop frames since power-on */
#define ADDR_RNG 0xFF0008        /* >u2 random state, stirred with the frame counter */
#define ADDR_END_X 0xFF000A      /* >u2 x of the act's goal post */
#define ADDR_START_X 0xFF000C    /* >u2 x where players (re)spawn */
#define ADDR_CAMERA_X 0xFF000E   /* >i2 left edge of the screen in level pixels */
#define ADDR_MODE_TIMER 0xFF0010 /* >u2 frames left on the act-clear / game-over screen */
#define ADDR_VBLANKS 0xFF0012    /* >u2 incremented by the VBlank interrupt */
#define ADDR_PAD1 0xFF0014       /* |u1 port 1 held: PAD_* bits below */
#define ADDR_PAD2 0xFF0015       /* |u1 port 2 held */
#define ADDR_PAD1_NEW 0xFF0016   /* |u1 port 1 newly pressed this frame */
#define ADDR_PAD2_NEW 0xFF0017   /* |u1 port 2 newly pressed this frame */
#define ADDR_HW_VERSION 0xFF0018 /* |u1 raw version register 0xA10001 at boot */
#define ADDR_TMSS 0xFF0019       /* |u1 1 if boot wrote "SEGA" to 0xA14000 */
#define ADDR_SELFTEST 0xFF001A   /* |u1 1 = multiply/divide helpers passed at boot */
#define ADDR_CRASH 0xFF001B      /* |u1 CPU exception vector number, 0 = none */
#define ADDR_LEVEL_WIDTH 0xFF001C /* >u2 width of the act in pixels */

/* --- Players: two 32-byte records ------------------------------------------ */
#define ADDR_P1 0xFF0020
#define ADDR_P2 0xFF0040
#define PLAYER_SIZE 0x20
#define P_X 0x00        /* >i2 x of the feet centre, level pixels */
#define P_Y 0x02        /* >i2 y of the feet (224 = bottom of the screen) */
#define P_XSUB 0x04     /* |u1 x fraction (1/256 px) */
#define P_YSUB 0x05     /* |u1 y fraction */
#define P_VX 0x06       /* >i2 x speed, 1/256 px per frame */
#define P_VY 0x08       /* >i2 y speed, 1/256 px per frame, + is down */
#define P_STATE 0x0A    /* |u1 PS_* below */
#define P_LIVES 0x0B    /* |u1 lives left */
#define P_SCORE 0x0C    /* >d4 score, 8 BCD digits */
#define P_RINGS 0x10    /* >u2 rings held */
#define P_ON_GROUND 0x12 /* |u1 1 when standing */
#define P_FACING 0x13   /* |u1 0 right, 1 left */
#define P_TIMER 0x14    /* >u2 frames into the death animation */
#define P_INVULN 0x16   /* |u1 invulnerability frames left (after a hit) */
#define P_JUMP_HELD 0x17 /* |u1 jump button held since the jump */
#define P_DEATHS 0x18   /* |u1 lives lost, all acts */
#define P_ANIM 0x19     /* |u1 animation counter */

/* --- Level contents ---------------------------------------------------------- */
#define ADDR_ENEMIES 0xFF0060 /* 8 records of 12 bytes: E_* */
#define ENEMY_SIZE 12
#define MAX_ENEMIES 8
#define E_X 0x00      /* >i2 feet centre */
#define E_Y 0x02      /* >i2 feet */
#define E_X0 0x04     /* >i2 patrol range */
#define E_X1 0x06     /* >i2 */
#define E_STATE 0x08  /* |u1 0 gone (defeated), 1 walking, 2 paused */
#define E_DIR 0x09    /* |i1 +1 right, -1 left */
#define E_PAUSE 0x0A  /* |u1 frames left paused (random) */
#define ADDR_ENEMY_COUNT 0xFF00C0 /* |u1 crawlers placed in the act */
#define ADDR_RING_COUNT 0xFF00C1  /* |u1 rings placed in the act */
#define ADDR_DRAWN_LEFT 0xFF00C2  /* >i2 first level column drawn in plane A */
#define ADDR_REDRAW 0xFF00C4      /* 4 x >i2 columns to redraw at next vblank, -1 = none */
#define ADDR_GROUND 0xFF0100      /* 1024 x |u1, one per 8-pixel column: GROUND_* */
#define MAX_COLUMNS 1024
#define ADDR_RINGS 0xFF0500       /* 64 rings of 4 bytes: >u2 column, |u1 row, |u1 taken */
#define MAX_RINGS 64

/* Game modes (ADDR_GAME_MODE). */
#define MODE_TITLE 0
#define MODE_PLAY 1
#define MODE_CLEAR 2    /* "ACT CLEAR" pause, then the next act */
#define MODE_GAMEOVER 3 /* "GAME OVER" pause, then the title */

/* Player states (P_STATE). */
#define PS_ALIVE 0
#define PS_DYING 1  /* falling off the screen; respawns or goes out */
#define PS_OUT 2    /* no lives left */
#define PS_ABSENT 3 /* player 2 before pressing a button on port 2 */

/* Pad bits (ADDR_PAD*), active high. */
#define PAD_UP 0x01
#define PAD_DOWN 0x02
#define PAD_LEFT 0x04
#define PAD_RIGHT 0x08
#define PAD_B 0x10
#define PAD_C 0x20
#define PAD_A 0x40
#define PAD_START 0x80
#define PAD_JUMP (PAD_A | PAD_B | PAD_C)

/* Ground column byte (ADDR_GROUND): height in tiles above the bottom of the
 * screen (0 = bottomless pit), plus spikes on top. */
#define GROUND_HEIGHT 0x1F
#define GROUND_SPIKES 0x20

#ifndef __ASSEMBLER__
#include "hw.h"

struct player {
    s16 x, y;
    u8 xsub, ysub;
    s16 vx, vy;
    u8 state, lives;
    u8 score[4];
    u16 rings;
    u8 on_ground, facing;
    u16 timer;
    u8 invuln, jump_held, deaths, anim;
    u8 spare[6];
};

struct enemy {
    s16 x, y;   /* feet centre */
    s16 x0, x1; /* patrol range */
    u8 state;   /* 0 defeated / unused, 1 walking, 2 paused */
    s8 dir;     /* +1 right, -1 left */
    u8 pause;   /* frames left standing still (random) */
    u8 spare;
};

struct ring {
    u16 col;
    u8 row, taken;
};

/* The whole fixed map as one struct at 0xFF0000. */
struct ram {
    u8 zone, act, game_mode, level_done;
    u32 frame;
    u16 rng, end_x, start_x;
    s16 camera_x;
    u16 mode_timer;
    u16 vblanks;
    u8 pad[2], pad_new[2];
    u8 hw_version, tmss, selftest, crash;
    u16 level_width;
    u8 spare1[2];
    struct player p[2];
    struct enemy enemies[MAX_ENEMIES];
    u8 enemy_count, ring_count;
    s16 drawn_left;
    s16 redraw[4];
    u8 spare2[0x100 - 0xCC];
    u8 ground[MAX_COLUMNS];
    struct ring rings[MAX_RINGS];
};

#define RAM (*(struct ram *)RAM_BASE)

#define OFF(field) ((unsigned long)&((struct ram *)0)->field)
_Static_assert(OFF(zone) == ADDR_ZONE - RAM_BASE, "zone");
_Static_assert(OFF(act) == ADDR_ACT - RAM_BASE, "act");
_Static_assert(OFF(game_mode) == ADDR_GAME_MODE - RAM_BASE, "game_mode");
_Static_assert(OFF(level_done) == ADDR_LEVEL_DONE - RAM_BASE, "level_done");
_Static_assert(OFF(frame) == ADDR_FRAME - RAM_BASE, "frame");
_Static_assert(OFF(rng) == ADDR_RNG - RAM_BASE, "rng");
_Static_assert(OFF(end_x) == ADDR_END_X - RAM_BASE, "end_x");
_Static_assert(OFF(start_x) == ADDR_START_X - RAM_BASE, "start_x");
_Static_assert(OFF(camera_x) == ADDR_CAMERA_X - RAM_BASE, "camera_x");
_Static_assert(OFF(mode_timer) == ADDR_MODE_TIMER - RAM_BASE, "mode_timer");
_Static_assert(OFF(vblanks) == ADDR_VBLANKS - RAM_BASE, "vblanks");
_Static_assert(OFF(pad) == ADDR_PAD1 - RAM_BASE, "pad");
_Static_assert(OFF(pad_new) == ADDR_PAD1_NEW - RAM_BASE, "pad_new");
_Static_assert(OFF(hw_version) == ADDR_HW_VERSION - RAM_BASE, "hw_version");
_Static_assert(OFF(tmss) == ADDR_TMSS - RAM_BASE, "tmss");
_Static_assert(OFF(selftest) == ADDR_SELFTEST - RAM_BASE, "selftest");
_Static_assert(OFF(crash) == ADDR_CRASH - RAM_BASE, "crash");
_Static_assert(OFF(level_width) == ADDR_LEVEL_WIDTH - RAM_BASE, "level_width");
_Static_assert(OFF(p) == ADDR_P1 - RAM_BASE, "p1");
_Static_assert(OFF(p[1]) == ADDR_P2 - RAM_BASE, "p2");
_Static_assert(sizeof(struct player) == PLAYER_SIZE, "player size");
_Static_assert(OFF(p[0].x) - OFF(p) == P_X, "P_X");
_Static_assert(OFF(p[0].y) - OFF(p) == P_Y, "P_Y");
_Static_assert(OFF(p[0].vx) - OFF(p) == P_VX, "P_VX");
_Static_assert(OFF(p[0].vy) - OFF(p) == P_VY, "P_VY");
_Static_assert(OFF(p[0].state) - OFF(p) == P_STATE, "P_STATE");
_Static_assert(OFF(p[0].lives) - OFF(p) == P_LIVES, "P_LIVES");
_Static_assert(OFF(p[0].score) - OFF(p) == P_SCORE, "P_SCORE");
_Static_assert(OFF(p[0].rings) - OFF(p) == P_RINGS, "P_RINGS");
_Static_assert(OFF(p[0].on_ground) - OFF(p) == P_ON_GROUND, "P_ON_GROUND");
_Static_assert(OFF(p[0].timer) - OFF(p) == P_TIMER, "P_TIMER");
_Static_assert(OFF(p[0].invuln) - OFF(p) == P_INVULN, "P_INVULN");
_Static_assert(OFF(p[0].deaths) - OFF(p) == P_DEATHS, "P_DEATHS");
_Static_assert(OFF(enemies) == ADDR_ENEMIES - RAM_BASE, "enemies");
_Static_assert(sizeof(struct enemy) == ENEMY_SIZE, "enemy size");
_Static_assert(OFF(enemies[0].x0) - OFF(enemies) == E_X0, "E_X0");
_Static_assert(OFF(enemies[0].state) - OFF(enemies) == E_STATE, "E_STATE");
_Static_assert(OFF(enemies[0].pause) - OFF(enemies) == E_PAUSE, "E_PAUSE");
_Static_assert(OFF(enemy_count) == ADDR_ENEMY_COUNT - RAM_BASE, "enemy_count");
_Static_assert(OFF(ring_count) == ADDR_RING_COUNT - RAM_BASE, "ring_count");
_Static_assert(OFF(drawn_left) == ADDR_DRAWN_LEFT - RAM_BASE, "drawn_left");
_Static_assert(OFF(redraw) == ADDR_REDRAW - RAM_BASE, "redraw");
_Static_assert(OFF(ground) == ADDR_GROUND - RAM_BASE, "ground");
_Static_assert(OFF(rings) == ADDR_RINGS - RAM_BASE, "rings");
_Static_assert(sizeof(struct ram) <= 0x1000, "fixed map overflows into .data");

#endif /* __ASSEMBLER__ */
#endif
