/*
 * VDP access.  The VDP is programmed through two ports: 0xC00004 (control:
 * register writes and address set-up) and 0xC00000 (data, auto-incremented
 * by register 15 after each access).  Only CPU writes are used, no DMA.
 */
#include "vdp.h"
#include "ram.h"

/* Register values for 320x224 (H40, V28), planes 64x32, VBlank interrupt. */
static const u8 init_regs[24] = {
    0x04, /* 0: no HBlank interrupt, colour mode on */
    0x34, /* 1: display OFF for now, VBlank interrupt on, DMA allowed, mode 5 */
    VRAM_PLANE_A >> 10, /* 2: plane A name table */
    VRAM_WINDOW >> 10,  /* 3: window name table */
    VRAM_PLANE_B >> 13, /* 4: plane B name table */
    VRAM_SPRITES >> 9,  /* 5: sprite attribute table */
    0x00, /* 6: unused */
    0x00, /* 7: backdrop = palette 0, colour 0 */
    0x00, 0x00, /* 8, 9: unused (Master System scroll) */
    0xFF, /* 10: HBlank counter */
    0x00, /* 11: full-screen horizontal and vertical scroll, no ext. interrupt */
    0x81, /* 12: H40 (320 pixels), no interlace, no shadow/highlight */
    VRAM_HSCROLL >> 10, /* 13: horizontal scroll table */
    0x00, /* 14: unused */
    0x02, /* 15: auto-increment 2 bytes */
    0x01, /* 16: planes 64 x 32 cells */
    0x00, /* 17: window horizontal position: none */
    0x00, /* 18: window vertical position: none (the HUD turns it on) */
    0x00, 0x00, 0x00, 0x00, 0x00, /* 19-23: DMA length and source */
};

void vdp_set_reg(u16 reg, u16 value)
{
    VDP_CTRL = 0x8000 | (reg << 8) | value;
}

void vdp_display(int on)
{
    vdp_set_reg(1, on ? 0x74 : 0x34);
}

/* Control words: bits 31-30 + 7-4 select the target (VRAM/CRAM/VSRAM),
 * the address is split between bits 29-16 and 1-0. */
static u32 addr_bits(u16 addr)
{
    return ((u32)(addr & 0x3FFF) << 16) | (addr >> 14);
}

void vdp_vram_write_addr(u16 addr)
{
    VDP_CTRL32 = 0x40000000 | addr_bits(addr);
}

static void cram_write_addr(u16 addr)
{
    VDP_CTRL32 = 0xC0000000 | addr_bits(addr);
}

static void vsram_write_addr(u16 addr)
{
    VDP_CTRL32 = 0x40000010 | addr_bits(addr);
}

void vdp_init(void)
{
    u16 i;
    (void)VDP_CTRL; /* reading the status register resets a half-written command */
    for (i = 0; i < 24; i++)
        vdp_set_reg(i, init_regs[i]);
    vdp_vram_write_addr(0); /* 64 KiB of VRAM */
    for (i = 0; i < 0x4000; i++)
        VDP_DATA32 = 0;
    cram_write_addr(0);     /* 4 palettes x 16 colours */
    for (i = 0; i < 64; i++)
        VDP_DATA = 0;
    vsram_write_addr(0);    /* 40 vertical scroll words */
    for (i = 0; i < 40; i++)
        VDP_DATA = 0;
}

void vdp_set_palette(u16 index, const u16 *colors)
{
    u16 i;
    cram_write_addr(index * 32);
    for (i = 0; i < 16; i++)
        VDP_DATA = colors[i];
}

void vdp_set_color(u16 index, u16 color)
{
    cram_write_addr(index * 2);
    VDP_DATA = color;
}

/* One art character -> colour index: '.' or ' ' = 0 (transparent),
 * '1'-'9', 'A'-'F' = that colour of the tile's palette. */
static u32 art_pixel(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return 0;
}

/* 8 art characters -> one 4bpp tile row (leftmost pixel in the top nibble). */
static u32 art_row(const char *art)
{
    u32 row = 0;
    u16 i;
    for (i = 0; i < 8; i++)
        row = (row << 4) | art_pixel(art[i]);
    return row;
}

/* An 8x8 tile from 64 art characters, row by row. */
void vdp_load_tile(u16 tile, const char *art)
{
    u16 r;
    vdp_vram_write_addr(tile * 32);
    for (r = 0; r < 8; r++)
        VDP_DATA32 = art_row(art + r * 8);
}

/* A 16x16 sprite from 256 art characters.  Sprite cells are stored column
 * by column: top-left, bottom-left, top-right, bottom-right. */
void vdp_load_sprite16(u16 tile, const char *art)
{
    u16 cx, cy, r;
    vdp_vram_write_addr(tile * 32);
    for (cx = 0; cx < 2; cx++)
        for (cy = 0; cy < 2; cy++)
            for (r = 0; r < 8; r++)
                VDP_DATA32 = art_row(art + (cy * 8 + r) * 16 + cx * 8);
}

void vdp_put(u16 plane, u16 col, u16 row, u16 attr)
{
    vdp_vram_write_addr(plane + ((row * PLANE_W + (col & (PLANE_W - 1))) << 1));
    VDP_DATA = attr;
}

/* Text: the font's tiles are indexed by ASCII code (see art.c). */
void vdp_text(u16 plane, u16 col, u16 row, const char *s, u16 attr)
{
    vdp_vram_write_addr(plane + ((row * PLANE_W + col) << 1));
    while (*s)
        VDP_DATA = attr + (u8)*s++;
}

void vdp_fill_plane(u16 plane, u16 attr)
{
    u16 i;
    vdp_vram_write_addr(plane);
    for (i = 0; i < PLANE_W * 32; i++)
        VDP_DATA = attr;
}

/* Full-screen scroll: one word per plane at the top of the table. */
void vdp_hscroll(s16 plane_a, s16 plane_b)
{
    vdp_vram_write_addr(VRAM_HSCROLL);
    VDP_DATA = plane_a;
    VDP_DATA = plane_b;
}

/* Sleep until the next VBlank interrupt (the handler counts them). */
void vdp_wait_vblank(void)
{
    volatile u16 *count = (volatile u16 *)ADDR_VBLANKS;
    u16 seen = *count;
    while (*count == seen)
        ;
    __asm__ volatile("" ::: "memory");
}
