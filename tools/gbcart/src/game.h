/*
 * Trekker's functions, by module.
 */
#ifndef TREKKER_GAME_H
#define TREKKER_GAME_H

#include <stdint.h>

/* boot/crt0.s */
void wait_vblank(void);
void oam_dma(void);

/* video.c: tiles, palettes, the level's columns, the HUD, sprites */
#define TILE_SKY 0
#define TILE_GRASS 1
#define TILE_DIRT 2
#define TILE_COIN 3
#define TILE_POLE 4
#define TILE_FLAG 5
#define TILE_CLOUD 6
#define TILE_HEAD 8
#define TILE_LEGS 9     /* 9 standing, 10 and 11 running */
#define TILE_WALKER 12  /* 12 and 13 */
#define TILE_DIGIT 16   /* '0'-'9' */
#define TILE_LETTER 26  /* the letters of FONT_LETTERS */

void video_init(void);
void lcd_off(void);
void lcd_on(void);
void set_palettes(void);
void draw_text(uint8_t row, uint8_t col, const char *text);
void clear_bg(void);
void draw_level_screen(void);
void prepare_column(uint8_t column);
void clear_coin_tile(uint8_t column);
void hud_show_score(void);
void hud_message(const char *text);
void vblank_work(void);
void build_sprites(void);

/* main.c */
void start_level(void);

/* levels.c */
#define LEVELS 3
void load_level_map(void);

/* play.c: the player, walkers, coins and the score */
void player_spawn(void);
void play_step(void);
void add_score(uint8_t byte, uint8_t bcd);

#endif
