#ifndef PLAYER_H
#define PLAYER_H

void player_spawn(void);
void player_die(void);
void player_update(void);
void crawlers_move(void);

#endif
