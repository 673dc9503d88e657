/* Skipper's fixed RAM map.
 *
 * Work RAM is the 8 KiB page $F8, mapped by the crt0 at logical $2000-$3FFF
 * (zero page $2000-$20FF, CPU stack $2100-$21FF). cc65's own zero-page
 * variables take $2000-$203F (pce.cfg); the game's variables are the rest of
 * the zero page, $2040-$206F, where PC Engine games keep theirs and where
 * retrokit's RAM view and click-to-find start. The crawler and coin tables and
 * the ground map are at $2200-$23FF; the linker config starts C's own data at
 * $2400. retrokit names a byte by its console address 0xF80000 + (logical -
 * $2000): $2040 is 0xF80040. games/Skipper-PCEngine/game.yaml repeats these
 * addresses; tests/test_pcecart.py checks the two agree. Multi-byte values are
 * little-endian (the 6502 family's order) except the score, 8 BCD digits
 * stored most significant byte first.
 */
#ifndef RAM_H
#define RAM_H

#define ADDR_LIVES       0x2040
#define ADDR_GAME_MODE   0x2041  /* 0 title, 1 playing, 2 level clear, 3 game over */
#define ADDR_LEVEL_DONE  0x2042  /* 1 from reaching end_x until the next level starts */
#define ADDR_LEVEL       0x2043  /* level select / current level, 0-2 */
#define ADDR_SCORE       0x2044  /* 4 bytes, 8 BCD digits, big-endian */
#define ADDR_FRAME       0x2048  /* main-loop frames since power-on, 16 bits */
#define ADDR_RNG         0x204A  /* random state, 16 bits */
#define ADDR_X           0x204C  /* player feet centre, level pixels, 16 bits */
#define ADDR_Y           0x204E  /* player feet, screen pixels, signed 16 bits; the usual floor is 208 */
#define ADDR_VX          0x2050  /* signed, 1/16 pixel a frame */
#define ADDR_VY          0x2051  /* signed, 1/16 pixel a frame, positive is down */
#define ADDR_XS          0x2052  /* x fraction, 1/16 pixel */
#define ADDR_YS          0x2053  /* y fraction, 1/16 pixel */
#define ADDR_STATE       0x2054  /* 0 alive, 1 dying */
#define ADDR_ON_GROUND   0x2055
#define ADDR_CAMERA_X    0x2056  /* left edge of the screen, level pixels, 16 bits */
#define ADDR_END_X       0x2058  /* the level's goal x, 16 bits */
#define ADDR_START_X     0x205A  /* spawn x, 16 bits */
#define ADDR_MODE_TIMER  0x205C  /* frames left on the clear / game-over screen */
#define ADDR_TIMER       0x205D  /* frames into the death animation */
#define ADDR_PAD         0x205E  /* held: 1 I, 2 II, 4 SELECT, 8 RUN, 16 up, 32 right, 64 down, 128 left */
#define ADDR_PAD_NEW     0x205F  /* pressed this frame */
#define ADDR_COINS       0x2060  /* coins taken this game */
#define ADDR_DEATHS      0x2061  /* lives lost this game */
#define ADDR_FACING      0x2062  /* 0 right, 1 left */
#define ADDR_ENEMY_COUNT 0x2063
#define ADDR_COIN_COUNT  0x2064
#define ADDR_LAG         0x2065  /* frames the main loop missed a vertical blank */
#define ADDR_LEVEL_WIDTH 0x2066  /* the level's width in pixels, 16 bits */
#define ADDR_DRAWN_COL   0x2068  /* next 8-pixel column to draw into the BAT, 16 bits */
#define ADDR_VBLANKS     0x206A  /* vertical-blank interrupts counted by cc65's tick counter, low byte */
#define ADDR_ENEMIES     0x2200  /* 6 x 10 bytes, see struct enemy */
#define ADDR_COINMAP     0x2240  /* 16 x 4 bytes, see struct coin */
#define ADDR_GROUND      0x2300  /* 256 bytes: ground height in tiles per 8-pixel column, 0 = pit */

#define MAX_ENEMIES 6
#define MAX_COINS 16

struct enemy {
    unsigned x;           /* +0 feet centre, level pixels */
    unsigned x0, x1;      /* +2, +4 patrol ends */
    unsigned char y;      /* +6 feet */
    unsigned char state;  /* +7 0 gone, 1 walking, 2 paused */
    signed char dir;      /* +8 -1 or 1 */
    unsigned char pause;  /* +9 frames left paused */
};

struct coin {
    unsigned col;         /* +0 8-pixel column */
    unsigned char row;    /* +2 tile row from the top */
    unsigned char taken;  /* +3 */
};

#define R8(a)  (*(unsigned char *)(a))
#define S8(a)  (*(signed char *)(a))
#define R16(a) (*(unsigned *)(a))
#define S16(a) (*(int *)(a))

#define LEVEL       R8(ADDR_LEVEL)
#define GAME_MODE   R8(ADDR_GAME_MODE)
#define LEVEL_DONE  R8(ADDR_LEVEL_DONE)
#define LIVES       R8(ADDR_LIVES)
#define SCORE       ((unsigned char *)ADDR_SCORE)
#define FRAME       R16(ADDR_FRAME)
#define RNG         R16(ADDR_RNG)
#define PX          R16(ADDR_X)
#define PY          S16(ADDR_Y)
#define VX          S8(ADDR_VX)
#define VY          S8(ADDR_VY)
#define XS          R8(ADDR_XS)
#define YS          R8(ADDR_YS)
#define PSTATE      R8(ADDR_STATE)
#define ON_GROUND   R8(ADDR_ON_GROUND)
#define CAMERA_X    R16(ADDR_CAMERA_X)
#define END_X       R16(ADDR_END_X)
#define START_X     R16(ADDR_START_X)
#define MODE_TIMER  R8(ADDR_MODE_TIMER)
#define TIMER       R8(ADDR_TIMER)
#define PAD         R8(ADDR_PAD)
#define PAD_NEW     R8(ADDR_PAD_NEW)
#define COINS       R8(ADDR_COINS)
#define DEATHS      R8(ADDR_DEATHS)
#define FACING      R8(ADDR_FACING)
#define ENEMY_COUNT R8(ADDR_ENEMY_COUNT)
#define COIN_COUNT  R8(ADDR_COIN_COUNT)
#define LAG         R8(ADDR_LAG)
#define LEVEL_WIDTH R16(ADDR_LEVEL_WIDTH)
#define DRAWN_COL   R16(ADDR_DRAWN_COL)
#define VBLANKS     R8(ADDR_VBLANKS)
#define ENEMY       ((struct enemy *)ADDR_ENEMIES)
#define COIN        ((struct coin *)ADDR_COINMAP)
#define GROUND      ((unsigned char *)ADDR_GROUND)

#define MODE_TITLE 0
#define MODE_PLAY 1
#define MODE_CLEAR 2
#define MODE_GAMEOVER 3

#define ALIVE 0
#define DYING 1

#define PAD_I 0x01
#define PAD_II 0x02
#define PAD_SELECT 0x04
#define PAD_RUN 0x08
#define PAD_UP 0x10
#define PAD_RIGHT 0x20
#define PAD_DOWN 0x40
#define PAD_LEFT 0x80

#endif
