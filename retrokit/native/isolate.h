#ifndef RETROKIT_ISOLATE_H
#define RETROKIT_ISOLATE_H

#include "core.h"

/* Point a loaded core copy's rand, srand, random and srandom at per-emulator
 * versions. Returns how many relocations were patched, or -1. */
int rk_isolate_core(rk_core *core);

void rk_rand_seed(rk_rand *r, unsigned seed);
int32_t rk_rand_next(rk_rand *r);

#endif
