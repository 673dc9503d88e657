/* Rings and crawlers. */
#ifndef DASHER_OBJECTS_H
#define DASHER_OBJECTS_H
#include "ram.h"

void enemies_update(void);
void objects_touch(struct player *p); /* collect rings, fight crawlers */

#endif
