/*
 * Shared between core.c (loading, running) and environment.c (what the core
 * calls back). Not part of the host's interface.
 */
#ifndef RETROKIT_CALLBACKS_H
#define RETROKIT_CALLBACKS_H

#include <stdbool.h>

#include "core.h"

/* The core the calling thread is inside of: libretro callbacks carry no context. */
extern _Thread_local rk_core *rk_current;

void rk_set_error(rk_core *core, const char *fmt, ...);
void rk_free_options(rk_core *core);

bool rk_cb_environment(unsigned cmd, void *data);
void rk_cb_video(const void *data, unsigned width, unsigned height, size_t pitch);
void rk_cb_audio_sample(int16_t left, int16_t right);
size_t rk_cb_audio_batch(const int16_t *data, size_t frames);
void rk_cb_input_poll(void);
int16_t rk_cb_input_state(unsigned port, unsigned device, unsigned index, unsigned id);

#endif
