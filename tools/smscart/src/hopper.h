/* Hopper: shared declarations. CONSOLE_GG (the Makefile's -DCONSOLE_GG=1 for
 * the Game Gear ROM) picks the screen window, the palette format and the pads. */
#ifndef HOPPER_H
#define HOPPER_H

#include <stdint.h>
#include "ram.h"

#ifndef CONSOLE_GG
#define CONSOLE_GG 0
#endif

/* The visible window in VDP screen pixels: the Game Gear's LCD shows the
 * 160x144 middle of the Master System's 256x192 picture. */
#if CONSOLE_GG
#define SCREEN_LEFT 48
#define SCREEN_TOP 24
#define SCREEN_W 160
#define PLAYERS 1
#else
#define SCREEN_LEFT 0
#define SCREEN_TOP 0
#define SCREEN_W 256
#define PLAYERS 2
#endif
#define SCREEN_BOTTOM (SCREEN_TOP + 144 + 48 * (1 - CONSOLE_GG)) /* 168 or 192 */

/* Tiles (pattern numbers); letters and digits use their ASCII codes. */
#define T_SKY 0
#define T_GRASS 1
#define T_DIRT 2
#define T_COIN 3
#define T_P1 4       /* 4, 5: player 1 top and bottom */
#define T_P2 6       /* 6, 7: player 2 */
#define T_CRAWLER 8  /* 8, 9: two walking frames */
#define T_FLAG 10

/* video.c */
void vdp_init(void);
void vdp_set_reg(uint8_t reg, uint8_t value);
void vdp_display(uint8_t on);
void vdp_put_tile(uint8_t col, uint8_t row, uint8_t tile);
void vdp_text(uint8_t col, uint8_t row, const char *text);
void vdp_clear_map(void);
void vdp_set_sky(uint8_t level);
void vdp_upload_sat(void);
void wait_vblank(void);
void read_pads(void);

/* world.c */
void world_load(uint8_t level);
void world_draw_ahead(void);
void world_redraw(void);
int16_t ground_top(uint16_t x);
uint8_t level_count(void);

/* actors.c */
void players_spawn(void);
void player_spawn(uint8_t i);
void players_update(void);
void crawlers_update(void);
void sprites_build(void);
void add_score(uint8_t i, uint16_t bcd);
uint8_t rand8(void);

#endif
