/*
 * Game Boy hardware registers (Pan Docs names), as memory-mapped bytes.
 */
#ifndef TREKKER_HW_H
#define TREKKER_HW_H

#include <stdint.h>

#define REG(a) (*(volatile uint8_t *)(a))

#define rP1 REG(0xFF00)    /* joypad: write 0x20 to read the d-pad, 0x10 the buttons */
#define rIF REG(0xFF0F)    /* interrupt flags */
#define rLCDC REG(0xFF40)  /* LCD control */
#define rSTAT REG(0xFF41)
#define rSCY REG(0xFF42)
#define rSCX REG(0xFF43)
#define rLY REG(0xFF44)
#define rDMA REG(0xFF46)
#define rBGP REG(0xFF47)   /* DMG palettes: two bits a shade per colour */
#define rOBP0 REG(0xFF48)
#define rOBP1 REG(0xFF49)
#define rWY REG(0xFF4A)
#define rWX REG(0xFF4B)
#define rBGPI REG(0xFF68)  /* CGB palette index (bit 7 auto-increment) and data */
#define rBGPD REG(0xFF69)
#define rOBPI REG(0xFF6A)
#define rOBPD REG(0xFF6B)
#define rNR52 REG(0xFF26)  /* sound on/off */
#define rIE REG(0xFFFF)

#define LCDC_ON 0x80
#define LCDC_WIN_9C00 0x40
#define LCDC_WIN_ON 0x20
#define LCDC_TILES_8000 0x10
#define LCDC_OBJ_ON 0x02
#define LCDC_BG_ON 0x01

#define VRAM_TILES ((volatile uint8_t *)0x8000)
#define BG_MAP ((volatile uint8_t *)0x9800)   /* 32x32 tiles, the level */
#define WIN_MAP ((volatile uint8_t *)0x9C00)  /* the HUD row */

#endif
