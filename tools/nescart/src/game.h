/* Hopper's functions, by module; the RAM they share is src/ram.h. */
#ifndef HOPPER_GAME_H
#define HOPPER_GAME_H

#include "ram.h"

/* ppu.c: the PPU write queue, text, frames */
void queue_flush(void);                       /* crt0.s */
unsigned char *queue_entry(unsigned addr, unsigned char count, unsigned char down);
void wait_frame(void);
void ppu_off(void);
void ppu_on(void);
void ppu_init(void);
void clear_nametables(void);
void text(unsigned addr, const char *s);
void screen_text(unsigned char column, unsigned char row, const char *s);
void read_pads(void);
unsigned char rnd(void);

/* world.c: stages, the ground map, columns */
void load_stage(void);
int ground_top(unsigned x);
void redraw(void);
void draw_ahead(void);

/* player.c */
void player_spawn(unsigned char n, unsigned x, int y);
void player_update(unsigned char n, unsigned char held, unsigned char pressed);
void player_die(unsigned char n);
void add_score(unsigned char n, unsigned char digit, unsigned char amount);
unsigned char leader(void);

/* enemy.c */
void enemies_update(void);

/* sprites.c */
void draw_sprites(void);

#endif
