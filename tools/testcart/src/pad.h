/* 3-button control pads on ports 1 and 2. */
#ifndef DASHER_PAD_H
#define DASHER_PAD_H
#include "hw.h"

void pad_init(void);
void pad_read_all(void); /* updates RAM.pad[] and RAM.pad_new[] */

#endif
