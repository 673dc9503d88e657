/* The VDC set up for a 256x240 screen, VRAM access, text, tiles and sprites. */
#include <pce.h>
#include "hw.h"
#include "ram.h"
#include "video.h"

unsigned char vblank_count(void);

#define SPRITES 16  /* sprites the game uses; the rest of the SATB stays hidden */

static unsigned satb[SPRITES * 4];
static unsigned char last_tick;

void vdc_reg(unsigned char reg, unsigned value) {
    VDC_SELECT = reg;
    VDC_LO = (unsigned char)value;
    VDC_HI = (unsigned char)(value >> 8);
}

void vram_seek(unsigned address) {
    vdc_reg(VDC_MAWR, address);
    VDC_SELECT = VDC_VWR;
}

void vram_put(unsigned word) {
    VDC_LO = (unsigned char)word;
    VDC_HI = (unsigned char)(word >> 8);
}

void set_color(unsigned index, unsigned color) {
    VCE_ADDR_LO = (unsigned char)index;
    VCE_ADDR_HI = (unsigned char)(index >> 8);
    VCE_DATA_LO = (unsigned char)color;
    VCE_DATA_HI = (unsigned char)(color >> 8);
}

void bat_put(unsigned char col, unsigned char row, unsigned entry) {
    vram_seek(VRAM_BAT + ((unsigned)row << 6) + (col & 63));
    vram_put(entry);
}

void bat_clear(void) {
    unsigned i;
    vram_seek(VRAM_BAT);
    for (i = 0; i < 64 * 32; ++i) {
        vram_put(0x100);  /* the blank tile */
    }
}

void text(unsigned char col, unsigned char row, const char *s) {
    while (*s) {
        bat_put(col++, row, 0x200 + (unsigned char)*s++);
    }
}

/* Sprite n's SATB entry: the VDC's sprite origin is (-32, -64) on screen. */
void sprite(unsigned char n, int x, int y, unsigned pattern, unsigned attr) {
    unsigned *e = &satb[n << 2];
    e[0] = (unsigned)(y + 64) & 0x3FF;
    e[1] = (unsigned)(x + 32) & 0x3FF;
    e[2] = pattern >> 5;
    e[3] = attr;
}

void sprites_hide_from(unsigned char n) {
    for (; n < SPRITES; ++n) {
        satb[n << 2] = 0;  /* y 0 is 64 lines above the screen */
    }
}

void sprites_flush(void) {
    unsigned char i;
    vram_seek(VRAM_SATB);
    for (i = 0; i < SPRITES * 4; ++i) {
        vram_put(satb[i]);
    }
}

/* Wait for the next vertical blank, unless the frame's work already ran past one. */
void wait_frame(void) {
    unsigned char now = vblank_count();
    if (now != last_tick) {
        ++LAG;
    } else {
        waitvsync();
    }
    last_tick = vblank_count();
    VBLANKS = last_tick;
}

static unsigned char pixel(char c) {
    if (c >= '1' && c <= '9') return (unsigned char)(c - '0');
    if (c >= 'A' && c <= 'F') return (unsigned char)(c - 'A' + 10);
    return 0;
}

/* A background tile from 64 characters of text art ('.' transparent, '1'-'F' colours). */
void load_tile(unsigned tile, const char *art) {
    static unsigned char planes[32];
    unsigned char row, col, p, bit;
    for (row = 0; row < 8; ++row) {
        planes[row * 2] = planes[row * 2 + 1] = planes[16 + row * 2] = planes[17 + row * 2] = 0;
        for (col = 0; col < 8; ++col) {
            p = pixel(art[row * 8 + col]);
            bit = 0x80 >> col;
            if (p & 1) planes[row * 2] |= bit;
            if (p & 2) planes[row * 2 + 1] |= bit;
            if (p & 4) planes[16 + row * 2] |= bit;
            if (p & 8) planes[17 + row * 2] |= bit;
        }
    }
    vram_seek(tile << 4);
    for (row = 0; row < 32; row += 2) {
        vram_put(planes[row] | (planes[row + 1] << 8));
    }
}

/* A 16x16 sprite pattern from width x height characters of text art, drawn at its top left. */
void load_sprite(unsigned address, const char *art, unsigned char width, unsigned char height) {
    static unsigned planes[64];
    unsigned char row, col, p, i;
    unsigned bit;
    for (i = 0; i < 64; ++i) planes[i] = 0;
    for (row = 0; row < height; ++row) {
        for (col = 0; col < width; ++col) {
            p = pixel(art[row * width + col]);
            bit = 0x8000 >> col;
            if (p & 1) planes[row] |= bit;
            if (p & 2) planes[16 + row] |= bit;
            if (p & 4) planes[32 + row] |= bit;
            if (p & 8) planes[48 + row] |= bit;
        }
    }
    vram_seek(address);
    for (i = 0; i < 64; ++i) vram_put(planes[i]);
}

void video_init(void) {
    VCE_CTRL = 0;                   /* 5.37 MHz dot clock: 256 pixels a line */
    vdc_reg(VDC_CR, 0);             /* display off while setting up */
    vdc_reg(VDC_MWR, 0x0010);       /* 64x32 background */
    vdc_reg(VDC_HSR, 0x0202);
    vdc_reg(VDC_HDR, 0x031F);       /* 32 tiles across */
    vdc_reg(VDC_VSR, 0x0F02);
    vdc_reg(VDC_VDR, 0x00EF);       /* 240 lines */
    vdc_reg(VDC_VCR, 0x0003);
    vdc_reg(VDC_BXR, 0);
    vdc_reg(VDC_BYR, 0);
    vdc_reg(VDC_DCR, 0x0010);       /* copy the SATB to the sprites every vertical blank */
    vdc_reg(VDC_SATB, VRAM_SATB);
    bat_clear();
    sprites_hide_from(0);
    sprites_flush();
    last_tick = vblank_count();
    vdc_reg(VDC_CR, 0x00C8);        /* background, sprites, vertical-blank interrupt */
    VDC_SELECT = VDC_VWR;
}
