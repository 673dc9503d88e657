/*
 * Genesis / Mega Drive hardware: fixed-width types and the memory-mapped
 * ports the cartridge touches.  Everything here is a plain address on the
 * 68000 bus; see tools/testcart/README.md for the map.
 */
#ifndef DASHER_HW_H
#define DASHER_HW_H

typedef unsigned char u8;
typedef signed char s8;
typedef unsigned short u16;
typedef signed short s16;
typedef unsigned long u32;
typedef signed long s32;

#define REG8(a) (*(volatile u8 *)(a))
#define REG16(a) (*(volatile u16 *)(a))
#define REG32(a) (*(volatile u32 *)(a))

/* VDP ports (any 16-bit access; the control port also takes 32-bit writes). */
#define VDP_DATA REG16(0xC00000)
#define VDP_DATA32 REG32(0xC00000)
#define VDP_CTRL REG16(0xC00004)
#define VDP_CTRL32 REG32(0xC00004)
#define PSG_PORT REG8(0xC00011)

/* I/O chip.  Odd addresses: the chip sits on the low byte of the bus. */
#define IO_VERSION REG8(0xA10001) /* bits 0-3: 0 = no TMSS, else TMSS present */
#define IO_DATA1 REG8(0xA10003)   /* port 1 (control pad 1) data */
#define IO_DATA2 REG8(0xA10005)   /* port 2 data */
#define IO_CTRL1 REG8(0xA10009)   /* port 1 direction: bit set = output pin */
#define IO_CTRL2 REG8(0xA1000B)

/* Z80 bus arbitration and reset lines (bit 8 of a word write). */
#define Z80_BUSREQ REG16(0xA11100)
#define Z80_RESET REG16(0xA11200)
#define Z80_RAM ((volatile u8 *)0xA00000)

#endif
