/*
 * Trekker's fixed RAM map.
 *
 * Everything a tool may want to read or write lives at a fixed address in the
 * first 512 bytes of work RAM (0xC000-0xC1FF); the linker places the
 * compiler's own variables at 0xC200 and above, and the stack grows down from
 * 0xE000.  The ADDR_* constants are the documentation: the game.yaml files of
 * both builds repeat them (tests/test_gbcart.py checks that they agree).
 *
 * Multi-byte values are little-endian, as the SM83 stores them; the score is
 * packed BCD, least significant byte first, as many Game Boy games keep it.
 */
#ifndef TREKKER_RAM_H
#define TREKKER_RAM_H

#include <stdint.h>


/* --- Level select: kept by the boot-time RAM clear (see boot/crt0.s) ------- */
#define ADDR_LEVEL 0xC000       /* |u1 level 0-2: at the title, the level START begins */
/* --- Game state ------------------------------------------------------------ */
#define ADDR_GAME_MODE 0xC001   /* |u1 MODE_* below */
#define ADDR_LEVEL_DONE 0xC002  /* |u1 1 from reaching end_x until the next level starts */
#define ADDR_HW_CGB 0xC003      /* |u1 1 if the console is a Game Boy Color (A = 0x11 at boot) */
#define ADDR_FRAME 0xC004       /* <u4 main-loop frames since power-on */
#define ADDR_RNG 0xC008         /* <u2 random state, stirred with the frame counter and the pad */
#define ADDR_END_X 0xC00A       /* <u2 the level's goal x */
#define ADDR_START_X 0xC00C     /* <u2 x where the player (re)spawns */
#define ADDR_CAMERA_X 0xC00E    /* <u2 left edge of the screen in level pixels */
#define ADDR_MODE_TIMER 0xC010  /* <u2 frames left on the clear / game-over screen */
#define ADDR_VBLANKS 0xC012     /* <u2 VBlank interrupts taken */
#define ADDR_PAD 0xC014         /* |u1 buttons held: PAD_* bits below */
#define ADDR_PAD_NEW 0xC015     /* |u1 buttons newly pressed this frame */
#define ADDR_LEVEL_WIDTH 0xC016 /* <u2 the level's width in pixels */
#define ADDR_ENEMY_COUNT 0xC018 /* |u1 walkers in the level */
#define ADDR_COLOR_BUILD 0xC019 /* |u1 1 in the Game Boy Color build (rom.gbc) */
#define ADDR_CRASH 0xC01A       /* |u1 1 if the CPU ran into erased ROM (rst 0x38), 0 = never */
#define ADDR_VBLANK_FLAG 0xC01B /* |u1 set by the VBlank interrupt, cleared by the main loop */

/* --- The player: one 32-byte record ---------------------------------------- */
#define ADDR_P1 0xC020
#define P_X 0x00        /* <i2 x of the feet centre, level pixels */
#define P_Y 0x02        /* <i2 y of the feet (136 = the usual floor's top, below 152 is a fall) */
#define P_XSUB 0x04     /* |u1 x fraction (1/256 px) */
#define P_YSUB 0x05     /* |u1 y fraction */
#define P_VX 0x06       /* <i2 x speed, 1/256 px per frame */
#define P_VY 0x08       /* <i2 y speed, 1/256 px per frame, + is down */
#define P_STATE 0x0A    /* |u1 PS_* below */
#define P_LIVES 0x0B    /* |u1 lives left */
#define P_SCORE 0x0C    /* <d4 score, 8 BCD digits, low byte first */
#define P_COINS 0x10    /* |u1 coins taken (this game) */
#define P_ON_GROUND 0x11 /* |u1 1 when standing */
#define P_FACING 0x12   /* |u1 0 right, 1 left */
#define P_TIMER 0x13    /* |u1 frames into the death animation */
#define P_DEATHS 0x14   /* |u1 lives lost so far */
#define P_JUMP_HELD 0x15 /* |u1 the jump button is still held since the jump */

/* --- Walkers: 8 records of 8 bytes ----------------------------------------- */
#define ADDR_ENEMIES 0xC040
#define ENEMY_MAX 8
#define E_X 0x00        /* <u2 x of the centre, level pixels */
#define E_X0 0x02       /* <u2 patrol's left end */
#define E_X1 0x04       /* <u2 patrol's right end */
#define E_STATE 0x06    /* |u1 0 gone, 1 walking, 2 paused */
#define E_INFO 0x07     /* |u1 bit 7: walking left; bits 0-6: pause frames left */

/* --- The level ---------------------------------------------------------------- */
#define ADDR_GROUND 0xC100      /* 256 bytes, one per 8-pixel column: bits 0-3 floor height in tiles
                                   (0 = pit, floor top = 136 - 8 * height), bit 7 a coin 3 tiles above */
#define MAX_COLUMNS 256

#define MODE_TITLE 0
#define MODE_PLAY 1
#define MODE_CLEAR 2
#define MODE_GAMEOVER 3

#define PS_ALIVE 0
#define PS_DYING 1
#define PS_OUT 2

/* Pad bits as the game keeps them (the P1 register's two halves, inverted). */
#define PAD_RIGHT 0x01
#define PAD_LEFT 0x02
#define PAD_UP 0x04
#define PAD_DOWN 0x08
#define PAD_A 0x10
#define PAD_B 0x20
#define PAD_SELECT 0x40
#define PAD_START 0x80

typedef struct {
    int16_t x, y;
    uint8_t xsub, ysub;
    int16_t vx, vy;
    uint8_t state, lives;
    uint8_t score[4];
    uint8_t coins, on_ground, facing, timer, deaths, jump_held;
} Player;

typedef struct {
    uint16_t x, x0, x1;
    uint8_t state, info;
} Enemy;

/* The variables at those addresses (ram.c places them with __at, so it skips these declarations). */
#ifndef TREKKER_RAM_C
extern uint8_t level, game_mode, level_done, hw_cgb;
extern uint16_t frame_lo, frame_hi, rng, end_x, start_x, camera_x, mode_timer, vblanks;
extern uint8_t pad, pad_new;
extern uint16_t level_width;
extern uint8_t enemy_count, color_build, crash;
extern Player player;
extern Enemy enemies[ENEMY_MAX];
extern uint8_t ground[MAX_COLUMNS];
#endif

#endif
