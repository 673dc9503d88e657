#ifndef RETROKIT_VIDEO_H
#define RETROKIT_VIDEO_H

#include <stddef.h>
#include <stdint.h>

#include "libretro_api.h"

/* Write a width x height x 3 RGB image of `frame` (in the core's pixel
 * format, rows `pitch` bytes apart) to `dst`. A missing frame is black.
 * Returns -1 for an unknown pixel format. */
int rk_frame_to_rgb(const void *frame, size_t pitch, unsigned width, unsigned height, int format, uint8_t *dst);

#endif
