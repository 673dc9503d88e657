/* Tiles and palettes.  Art is written as text in art.c and font.c and
 * converted to 4-bit tiles when loaded into VRAM. */
#ifndef DASHER_ART_H
#define DASHER_ART_H
#include "hw.h"

/* Tile indices in VRAM (32 bytes each, from address 0). */
#define T_BLANK 0
#define T_GRASS 1
#define T_DIRT 2
#define T_DIRT_DEEP 3
#define T_SPIKES 4
#define T_RING 5
#define T_POLE 6
#define T_SIGN 7
#define T_CLOUD_L 8
#define T_CLOUD_M 9
#define T_CLOUD_R 10
#define T_HILL_UP 11
#define T_HILL_DOWN 12
#define T_HILL 13
#define T_STAR 14
#define T_HUD_BG 15
#define T_FONT 0       /* text tiles are T_FONT + ASCII code, 32..95 */
#define T_PLAYER 96    /* 4 frames x 4 cells: stand, run 1, run 2, ball */
#define T_ENEMY 112    /* 2 frames x 4 cells */

#define PLAYER_STAND 0
#define PLAYER_RUN1 1
#define PLAYER_RUN2 2
#define PLAYER_BALL 3

/* Palettes: 0 terrain + text (changes per zone), 1 player 1, 2 player 2,
 * 3 enemies + HUD labels. */
#define PAL_TERRAIN 0
#define PAL_P1 1
#define PAL_P2 2
#define PAL_ENEMY 3

void art_load(void);              /* all tiles and the fixed palettes */
void art_zone_palette(u16 zone);  /* palette 0 for a zone, 0-2 */

#endif
