/*
 * Hopper's fixed RAM map.
 *
 * Everything a tool may want to read or write lives at a fixed address in the
 * NES's 2 KiB of internal RAM (0x0000-0x07FF, which retrokit sees at console
 * address 0x0).  The ADDR_* constants are the documentation:
 * games/Hopper-Nes/game.yaml repeats them, and tests/test_nescart.py checks
 * that the two agree and plays the game to see each field hold what it says.
 * The structs below must follow the offsets by hand: cc65 2.19 has no
 * _Static_assert and does not fold offsetof into a constant expression.
 *
 * Multi-byte numbers are little-endian, as the 6502 stores them; scores are
 * six decimal digits, one a byte, most significant first (type >n6), the way
 * most NES games keep theirs.
 *
 *   0x0000-0x003F  cc65's zero-page registers
 *   0x0040-0x007F  game state (this file), in the zero page as NES games keep
 *                  theirs: the 6502 reaches it with shorter, faster instructions
 *   0x0080-0x00BF  two players
 *   0x0100-0x01FF  6502 stack
 *   0x0200-0x02FF  sprite table (OAM shadow, copied by DMA every frame)
 *   0x0300-0x034F  crawlers
 *   0x0400-0x04FF  ground map, one byte per 16-pixel column
 *   0x0500-0x057F  PPU write queue, emptied by the NMI handler
 *   0x0580-0x05FF  the compiler's own data
 *   0x0600-0x07FF  cc65's parameter stack
 */
#ifndef HOPPER_RAM_H
#define HOPPER_RAM_H

/* --- Level select: kept by the boot-time RAM clear (see crt0.s) ----------- */
#define ADDR_WORLD 0x0040       /* |u1 world 0-2: at the title, the world START begins */
#define ADDR_STAGE 0x0041       /* |u1 stage 0-1: likewise */
/* --- Game state ------------------------------------------------------------ */
#define ADDR_GAME_MODE 0x0042   /* |u1 MODE_* below */
#define ADDR_LEVEL_DONE 0x0043  /* |u1 1 from reaching end_x until the next stage */
#define ADDR_FRAME 0x0044       /* <u4 main-loop frames since power-on */
#define ADDR_RNG 0x0048         /* <u2 random state, stirred with the frame counter and pads */
#define ADDR_END_X 0x004A       /* <u2 x of the goal pole */
#define ADDR_START_X 0x004C     /* <u2 x where players (re)spawn */
#define ADDR_CAMERA_X 0x004E    /* <u2 left edge of the screen in level pixels */
#define ADDR_MODE_TIMER 0x0050  /* <u2 frames left on the clear / game-over screen */
#define ADDR_VBLANKS 0x0052     /* <u2 incremented by the NMI handler */
#define ADDR_PAD1 0x0054        /* |u1 port 1 held: PAD_* bits below */
#define ADDR_PAD2 0x0055        /* |u1 port 2 held */
#define ADDR_PAD1_NEW 0x0056    /* |u1 port 1 newly pressed this frame */
#define ADDR_PAD2_NEW 0x0057    /* |u1 port 2 newly pressed this frame */
#define ADDR_LEVEL_WIDTH 0x0058 /* <u2 width of the stage in pixels */
#define ADDR_ENEMY_COUNT 0x005A /* |u1 crawlers in the stage */
#define ADDR_COIN_COUNT 0x005B  /* |u1 coins in the stage at its start */
#define ADDR_NMI_READY 0x005C   /* |u1 1: the NMI handler may copy OAM, the queue and scroll */
#define ADDR_PPU_CTRL 0x005D    /* |u1 value the NMI handler writes to PPUCTRL */
#define ADDR_PPU_MASK 0x005E    /* |u1 value the NMI handler writes to PPUMASK */
#define ADDR_SCROLL_X 0x005F    /* |u1 value the NMI handler writes to PPUSCROLL */
#define ADDR_DRAW_COL 0x0060    /* <u2 next 8-pixel column of the stage to draw */
#define ADDR_QUEUE_LEN 0x0062   /* |u1 bytes in the PPU write queue */
#define ADDR_PLAYERS 0x0063     /* |u1 players in the game, 1 or 2 */

/* --- Players: two 32-byte records ------------------------------------------ */
#define ADDR_P1 0x0080
#define ADDR_P2 0x00A0
#define PLAYER_SIZE 0x20
#define P_X 0x00         /* <u2 x of the feet centre, level pixels */
#define P_Y 0x02         /* <i2 y of the feet; the lowest floor is 208, below 248 is a fall */
#define P_XSUB 0x04      /* |u1 x fraction (1/16 px) */
#define P_YSUB 0x05      /* |u1 y fraction */
#define P_VX 0x06        /* |i1 x speed, 1/16 px per frame */
#define P_VY 0x07        /* |i1 y speed, 1/16 px per frame, + is down */
#define P_STATE 0x08     /* |u1 PS_* below */
#define P_LIVES 0x09     /* |u1 lives left */
#define P_SCORE 0x0A     /* >n6 score, six digits, one a byte */
#define P_COINS 0x10     /* |u1 coins taken */
#define P_ON_GROUND 0x11 /* |u1 1 when standing */
#define P_FACING 0x12    /* |u1 0 right, 1 left */
#define P_TIMER 0x13     /* |u1 frames into the death animation */
#define P_DEATHS 0x14    /* |u1 lives lost so far */
#define P_JUMP_HELD 0x15 /* |u1 jump held since the jump began */

/* --- Crawlers: eight 10-byte records --------------------------------------- */
#define ADDR_ENEMIES 0x0300
#define ENEMY_SIZE 10
#define MAX_ENEMIES 8
#define E_X 0x00     /* <u2 centre x */
#define E_X0 0x02    /* <u2 patrol left end */
#define E_X1 0x04    /* <u2 patrol right end */
#define E_Y 0x06     /* |u1 feet y */
#define E_STATE 0x07 /* |u1 ES_* below */
#define E_DIR 0x08   /* |i1 1 right, -1 left */
#define E_PAUSE 0x09 /* |u1 frames left paused at a patrol end */

/* --- Big tables -------------------------------------------------------------- */
#define ADDR_GROUND 0x0400 /* one byte per 16-px column: height 0-4 (0 = pit), bit 7 = coin */
#define GROUND_COIN 0x80
#define ADDR_OAM 0x0200
#define ADDR_QUEUE 0x0500
#define QUEUE_SIZE 0x80

#define MODE_TITLE 0
#define MODE_PLAY 1
#define MODE_CLEAR 2
#define MODE_GAMEOVER 3

#define PS_ALIVE 0
#define PS_DYING 1
#define PS_OUT 2
#define PS_ABSENT 3

#define ES_GONE 0
#define ES_WALK 1
#define ES_PAUSE 2

/* Pad bits as the game reads them from $4016/$4017 (A first, RIGHT last). */
#define PAD_RIGHT 0x01
#define PAD_LEFT 0x02
#define PAD_DOWN 0x04
#define PAD_UP 0x08
#define PAD_START 0x10
#define PAD_SELECT 0x20
#define PAD_B 0x40
#define PAD_A 0x80
#define PAD_JUMP (PAD_A | PAD_B)

struct player {
    unsigned x;
    int y;
    unsigned char xsub, ysub;
    signed char vx, vy;
    unsigned char state, lives;
    unsigned char score[6];
    unsigned char coins, on_ground, facing, timer, deaths, jump_held;
};

struct enemy {
    unsigned x, x0, x1;
    unsigned char y, state;
    signed char dir;
    unsigned char pause;
};

#define BYTE(a) (*(volatile unsigned char *)(a))
#define WORD(a) (*(volatile unsigned *)(a))

#define world BYTE(ADDR_WORLD)
#define stage BYTE(ADDR_STAGE)
#define game_mode BYTE(ADDR_GAME_MODE)
#define level_done BYTE(ADDR_LEVEL_DONE)
#define frame_lo WORD(ADDR_FRAME)
#define frame_hi WORD(ADDR_FRAME + 2)
#define rng WORD(ADDR_RNG)
#define end_x WORD(ADDR_END_X)
#define start_x WORD(ADDR_START_X)
#define camera_x WORD(ADDR_CAMERA_X)
#define mode_timer WORD(ADDR_MODE_TIMER)
#define vblanks WORD(ADDR_VBLANKS)
#define pad1 BYTE(ADDR_PAD1)
#define pad2 BYTE(ADDR_PAD2)
#define pad1_new BYTE(ADDR_PAD1_NEW)
#define pad2_new BYTE(ADDR_PAD2_NEW)
#define level_width WORD(ADDR_LEVEL_WIDTH)
#define enemy_count BYTE(ADDR_ENEMY_COUNT)
#define coin_count BYTE(ADDR_COIN_COUNT)
#define nmi_ready BYTE(ADDR_NMI_READY)
#define ppu_ctrl BYTE(ADDR_PPU_CTRL)
#define ppu_mask BYTE(ADDR_PPU_MASK)
#define scroll_x BYTE(ADDR_SCROLL_X)
#define draw_col WORD(ADDR_DRAW_COL)
#define queue_len BYTE(ADDR_QUEUE_LEN)
#define players BYTE(ADDR_PLAYERS)

#define PLAYER(n) ((struct player *)(ADDR_P1 + (n) * PLAYER_SIZE))
#define ENEMY(n) ((struct enemy *)(ADDR_ENEMIES + (n) * ENEMY_SIZE))
#define ground ((unsigned char *)ADDR_GROUND)
#define oam ((unsigned char *)ADDR_OAM)
#define queue ((unsigned char *)ADDR_QUEUE)

#endif
