/* The level as a world: the RAM ground map, terrain drawing, the camera. */
#ifndef DASHER_WORLD_H
#define DASHER_WORLD_H
#include "hw.h"

#define NO_GROUND 0x7FFF /* ground_y() over a pit */
#define SCREEN_W 320
#define SCREEN_H 224
#define VIEW_COLS 42     /* plane A columns kept drawn around the camera */

void world_load(u16 zone, u16 act);  /* expand the act into RAM and draw it */
u8 world_ground(s16 x);              /* GROUND_* byte under pixel column x */
s16 world_ground_y(s16 x);           /* y of the floor under x, or NO_GROUND */
void world_follow(s16 focus_x);      /* move the camera to keep focus_x in view */
void world_scroll(void);             /* at vblank: draw newly visible columns */
void world_redraw(s16 col);          /* queue a column redraw (a ring was taken) */
void world_draw_background(u16 zone);

#endif
