#ifndef ART_H
#define ART_H

/* Background tile numbers (VRAM word address / 16) and their palettes. */
#define T_BLANK 0x100
#define T_GRASS 0x101
#define T_DIRT 0x102
#define T_COIN 0x103
#define T_POLE 0x104
#define T_FLAG 0x105
#define PAL_TERRAIN 0x1000  /* BAT palette 1 */

/* Sprite patterns (VRAM word addresses) and palettes. */
#define S_PLAYER 0x4000
#define S_CRAWLER 0x4040
#define S_HEART 0x4080
#define S_DIGITS 0x40C0   /* ten patterns, 0x40 words apart */
#define SPR_FRONT 0x0080  /* drawn over the background */
#define SPR_FLIP_X 0x0800
#define SPR_PAL_PLAYER 0
#define SPR_PAL_CRAWLER 1
#define SPR_PAL_HUD 2

void art_init(void);

#endif
