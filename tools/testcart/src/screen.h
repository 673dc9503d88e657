/* What is drawn each frame: sprites, the HUD, the title and banners. */
#ifndef DASHER_SCREEN_H
#define DASHER_SCREEN_H
#include "hw.h"

void screen_title_draw(void);    /* whole title screen (display off) */
void screen_title_update(void);  /* at vblank on the title */
void screen_play_update(void);   /* at vblank in an act */
void screen_banner(const char *text); /* centred text over the act */

#endif
