/* Player physics: running, jumping, landing, walls, pits, spikes, death. */
#ifndef DASHER_PLAYER_H
#define DASHER_PLAYER_H
#include "ram.h"

#define START_LIVES 3
#define PLAYER_HALF_W 5   /* hit box: x-5..x+5 */
#define PLAYER_H 15       /* hit box: y-15..y */

void player_update(struct player *p, u16 index, u8 held, u8 pressed);
void player_spawn(struct player *p, u16 index); /* at the act's start */
void player_hurt(struct player *p);
void player_die(struct player *p);

#endif
