/* PC Engine hardware: the HuC6270 VDC, the HuC6260 VCE and the joypad port.
 *
 * The I/O page is mapped at logical $0000 (MPR0 = $FF). The VDC's ports are
 * reached through their mirror at $0200, because the HuC6280 sends
 * zero-page accesses to $2000 and cc65 would shorten $0000 to a zero-page
 * address.
 */
#ifndef HW_H
#define HW_H

#define VDC_SELECT (*(volatile unsigned char *)0x0200) /* write: register number; read: status */
#define VDC_LO     (*(volatile unsigned char *)0x0202)
#define VDC_HI     (*(volatile unsigned char *)0x0203) /* writing the high byte stores the word */
#define VCE_CTRL   (*(volatile unsigned char *)0x0400)
#define VCE_ADDR_LO (*(volatile unsigned char *)0x0402)
#define VCE_ADDR_HI (*(volatile unsigned char *)0x0403)
#define VCE_DATA_LO (*(volatile unsigned char *)0x0404)
#define VCE_DATA_HI (*(volatile unsigned char *)0x0405)
#define JOYPAD     (*(volatile unsigned char *)0x1000)

/* VDC registers */
#define VDC_MAWR 0x00
#define VDC_VWR 0x02
#define VDC_CR 0x05
#define VDC_BXR 0x07
#define VDC_BYR 0x08
#define VDC_MWR 0x09
#define VDC_HSR 0x0A
#define VDC_HDR 0x0B
#define VDC_VSR 0x0C
#define VDC_VDR 0x0D
#define VDC_VCR 0x0E
#define VDC_DCR 0x0F
#define VDC_SATB 0x13

/* VRAM layout, in 16-bit words */
#define VRAM_BAT 0x0000      /* 64 x 32 background attribute table */
#define VRAM_TILES 0x1000    /* our background tiles, from tile number 0x100 */
#define VRAM_FONT 0x2000     /* cc65's conio font, tile number 0x200 + ASCII */
#define VRAM_SPRITES 0x4000  /* 16x16 sprite patterns, 64 words each */
#define VRAM_SATB 0x7F00     /* sprite attribute table, copied to the VDC every vertical blank */

#endif
