/* VDP (video display processor) access: registers, VRAM/CRAM/VSRAM writes,
 * tiles from text art, text on the planes, and the vblank wait. */
#ifndef DASHER_VDP_H
#define DASHER_VDP_H
#include "hw.h"

/* VRAM layout, set by the registers in vdp_init(). */
#define VRAM_WINDOW 0xB000  /* window plane (HUD), 64 x 32 cells */
#define VRAM_PLANE_A 0xC000 /* level terrain, 64 x 32 cells */
#define VRAM_PLANE_B 0xE000 /* background, 64 x 32 cells */
#define VRAM_SPRITES 0xF000 /* sprite attribute table, 80 entries */
#define VRAM_HSCROLL 0xFC00 /* horizontal scroll table */
#define PLANE_W 64          /* cells per plane row */

/* Name-table entry: priority, palette 0-3, flips, tile index. */
#define TILE_ATTR(pal, prio, hflip, tile) \
    (((prio) << 15) | ((pal) << 13) | ((hflip) << 11) | (tile))

void vdp_init(void);
void vdp_set_reg(u16 reg, u16 value);
void vdp_display(int on);
void vdp_vram_write_addr(u16 addr);
void vdp_set_palette(u16 index, const u16 *colors);
void vdp_set_color(u16 index, u16 color);
void vdp_load_tile(u16 tile, const char *art);
void vdp_load_sprite16(u16 tile, const char *art);
void vdp_put(u16 plane, u16 col, u16 row, u16 attr);
void vdp_text(u16 plane, u16 col, u16 row, const char *s, u16 attr);
void vdp_fill_plane(u16 plane, u16 attr);
void vdp_hscroll(s16 plane_a, s16 plane_b);
void vdp_wait_vblank(void);

#endif
