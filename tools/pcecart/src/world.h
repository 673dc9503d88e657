#ifndef WORLD_H
#define WORLD_H

#define NO_FLOOR 1000

int floor_at(int x);
void world_load(void);
void world_draw(void);
void world_scroll(void);
void camera_follow(void);
void take_coin(unsigned char i);

#endif
