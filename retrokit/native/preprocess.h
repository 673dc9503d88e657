/*
 * Turning a core's frames into an agent's observation natively: crop,
 * grayscale, max-pool of a step's last two frames, resize and frame stack,
 * done on the thread that ran the frames, with the GIL released.
 */
#ifndef RETROKIT_PREPROCESS_H
#define RETROKIT_PREPROCESS_H

#include <stddef.h>
#include <stdint.h>

enum { RK_RESIZE_NONE, RK_RESIZE_AREA, RK_RESIZE_BILINEAR, RK_RESIZE_NEAREST };

/* What an observation is made of; checked in Python (envs/preprocessing.py), checked again here. */
typedef struct {
    unsigned screen_height, screen_width;       /* the screen the observation is made from */
    unsigned top, bottom, left, right;          /* pixels cropped off each edge */
    unsigned height, width;                     /* after resizing (the cropped size without) */
    int method;                                 /* RK_RESIZE_* */
    int gray;                                   /* one luma channel instead of RGB */
    int max_pool;                               /* max of a step's last two frames */
    unsigned stack;                             /* frames stacked, 1 for none */
    int channels_first;                         /* (C*stack, H, W) instead of (H, W, C*stack) */
} rk_prep_spec;

struct rk_core;
typedef struct rk_prep rk_prep;

/* A preprocessor for `spec`, or NULL (with `error` filled) if the spec is wrong or memory is short. */
rk_prep *rk_prep_new(const rk_prep_spec *spec, char *error, size_t error_size);
void rk_prep_free(rk_prep *p);
/* The bytes of one observation. */
size_t rk_prep_obs_size(const rk_prep *p);
/* Whether the frame before a run's last one must be drawn and kept (max_pool). */
int rk_prep_wants_previous(const rk_prep *p);
/* Keep the core's current frame as the step's next-to-last (called by the run loop). */
void rk_prep_keep(rk_prep *p, const struct rk_core *core);
/* Forget the kept frame and the stack: the next observation starts an episode. */
void rk_prep_restart(rk_prep *p);
/* Make the observation from the core's current frame (maxed with the kept one, if any) into dst.
 * After a restart the stack is filled with this frame, as Gymnasium's FrameStackObservation pads. */
void rk_prep_observe(rk_prep *p, const struct rk_core *core, uint8_t *dst);
/* The same from a packed RGB frame of height x width x 3. */
void rk_prep_observe_rgb(rk_prep *p, const uint8_t *rgb, unsigned width, unsigned height, uint8_t *dst);

#endif
