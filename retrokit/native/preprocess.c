/*
 * Native observation preprocessing: what Gymnasium's wrappers do in Python,
 * per env and per step, done here on the thread that ran the frames.
 *
 * The order is fixed: crop, then grayscale (GrayscaleObservation's luma,
 * truncated to uint8 as it does), then the max with the step's next-to-last
 * frame, then the resize (OpenCV's INTER_AREA, INTER_LINEAR or INTER_NEAREST
 * arithmetic, as ResizeObservation calls it), then the frame stack.
 *
 * A resize is separable: each output column (row) is a weighted sum of a few
 * input columns (rows), so the taps are computed once, and an observation is
 * a horizontal pass into floats and a vertical pass into bytes, rounded to
 * nearest-even as OpenCV's saturate_cast does.
 */
#include "preprocess.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core.h"
#include "video.h"

/* One axis of a resize: output i is the sum over first[i] <= t < first[i+1] of weight[t] * input[index[t]]. */
typedef struct {
    int *first, *index;
    float *weight;
} rk_taps;

struct rk_prep {
    rk_prep_spec s;
    unsigned ch;              /* channels of a frame: 1 or 3 */
    unsigned crop_h, crop_w;  /* the cropped frame's size */
    uint8_t *row;             /* one cropped row as RGB */
    uint8_t *cur, *kept;      /* crop_h x crop_w x ch: this frame, and the step's next-to-last */
    int have_kept;
    float *pass;              /* crop_h x width x ch: the horizontal pass */
    rk_taps tx, ty;
    uint8_t *frames;          /* stack x height x width x ch: a ring of the last frames */
    unsigned head;            /* the slot of the newest frame */
    int fresh;                /* the next observation starts an episode: it fills the stack */
};

/* ---- resize taps, as OpenCV's resize computes them --------------------------------------------- */

static int taps_alloc(rk_taps *t, unsigned out, unsigned per) {
    t->first = calloc(out + 1, sizeof(int));
    t->index = calloc((size_t)out * per, sizeof(int));
    t->weight = calloc((size_t)out * per, sizeof(float));
    return t->first && t->index && t->weight ? 0 : -1;
}

static void taps_free(rk_taps *t) {
    free(t->first);
    free(t->index);
    free(t->weight);
}

/* Two taps, sx and sx + 1, weighted 1 - fx and fx; clamped at the edges as OpenCV clamps. */
static int linear_pair(const rk_taps *t, int n, int k, int sx, float fx) {
    if (sx < 0) sx = 0, fx = 0;
    if (sx >= n - 1) sx = n - 1, fx = 0;
    t->index[k] = sx;
    t->weight[k++] = 1.0f - fx;
    if (fx != 0) {
        t->index[k] = sx + 1;
        t->weight[k++] = fx;
    }
    return k;
}

/* The taps mapping n inputs to m outputs. `area` is OpenCV's INTER_AREA when both axes shrink;
 * `area_up` its INTER_AREA when either grows (a linear blend of its own). */
static int taps_make(rk_taps *t, int method, int n, int m, int area_up) {
    double scale = 1.0 / ((double)m / n); /* as OpenCV computes it, to the last bit */
    unsigned per = method == RK_RESIZE_AREA && !area_up ? (unsigned)ceil(scale) + 2 : 2;
    if (taps_alloc(t, (unsigned)m, per)) return -1;
    int k = 0;
    for (int i = 0; i < m; i++) {
        t->first[i] = k;
        if (method == RK_RESIZE_NEAREST) {
            int sx = (int)floor(i * scale);
            t->index[k] = sx < n - 1 ? sx : n - 1;
            t->weight[k++] = 1.0f;
        } else if (method == RK_RESIZE_BILINEAR) {
            float fx = (float)((i + 0.5) * scale - 0.5);
            int sx = (int)floorf(fx);
            k = linear_pair(t, n, k, sx, fx - (float)sx);
        } else if (area_up) {
            int sx = (int)floor(i * scale);
            float fx = (float)((i + 1) - (sx + 1) / scale);
            fx = fx <= 0 ? 0.f : fx - floorf(fx);
            k = linear_pair(t, n, k, sx, fx);
        } else { /* OpenCV's computeResizeAreaTab */
            double fsx1 = i * scale, fsx2 = fsx1 + scale;
            double cell = fmin(scale, n - fsx1);
            int sx1 = (int)ceil(fsx1), sx2 = (int)floor(fsx2);
            sx2 = sx2 < n - 1 ? sx2 : n - 1;
            sx1 = sx1 < sx2 ? sx1 : sx2;
            if (sx1 - fsx1 > 1e-3) {
                t->index[k] = sx1 - 1;
                t->weight[k++] = (float)((sx1 - fsx1) / cell);
            }
            for (int sx = sx1; sx < sx2; sx++) {
                t->index[k] = sx;
                t->weight[k++] = (float)(1.0 / cell);
            }
            if (fsx2 - sx2 > 1e-3) {
                t->index[k] = sx2;
                t->weight[k++] = (float)(fmin(fmin(fsx2 - sx2, 1.0), cell) / cell);
            }
        }
    }
    t->first[m] = k;
    return 0;
}

/* ---- making and freeing ------------------------------------------------------------------------ */

void rk_prep_free(rk_prep *p) {
    if (!p) return;
    free(p->row);
    free(p->cur);
    free(p->kept);
    free(p->pass);
    free(p->frames);
    taps_free(&p->tx);
    taps_free(&p->ty);
    free(p);
}

rk_prep *rk_prep_new(const rk_prep_spec *s, char *error, size_t error_size) {
    const unsigned limit = 1u << 14; /* no console screen, nor a sensible observation, is larger */
    if (!s->screen_height || !s->screen_width || s->screen_height > limit || s->screen_width > limit ||
        s->top + s->bottom >= s->screen_height || s->left + s->right >= s->screen_width || !s->height ||
        !s->width || s->height > limit || s->width > limit || s->stack < 1 || s->stack > 256 ||
        s->method < RK_RESIZE_NONE || s->method > RK_RESIZE_NEAREST) {
        snprintf(error, error_size, "the preprocessing of a %ux%u screen to %ux%u, stack %u, is out of range",
                 s->screen_width, s->screen_height, s->width, s->height, s->stack);
        return NULL;
    }
    rk_prep *p = calloc(1, sizeof *p);
    if (!p) goto nomem;
    p->s = *s;
    p->ch = s->gray ? 1 : 3;
    p->crop_h = s->screen_height - s->top - s->bottom;
    p->crop_w = s->screen_width - s->left - s->right;
    if (s->method == RK_RESIZE_NONE && (s->height != p->crop_h || s->width != p->crop_w)) {
        snprintf(error, error_size, "without a resize the observation is the cropped %ux%u, not %ux%u", p->crop_w,
                 p->crop_h, s->width, s->height);
        rk_prep_free(p);
        return NULL;
    }
    size_t frame = (size_t)p->crop_h * p->crop_w * p->ch, small = (size_t)s->height * s->width * p->ch;
    p->row = malloc((size_t)p->crop_w * 3);
    p->cur = malloc(frame);
    p->kept = malloc(frame);
    p->frames = calloc(s->stack, small);
    if (!p->row || !p->cur || !p->kept || !p->frames) goto nomem;
    if (s->method != RK_RESIZE_NONE) {
        int area_up = s->method == RK_RESIZE_AREA && (s->height > p->crop_h || s->width > p->crop_w);
        p->pass = malloc((size_t)p->crop_h * s->width * p->ch * sizeof(float));
        if (!p->pass || taps_make(&p->tx, s->method, (int)p->crop_w, (int)s->width, area_up) ||
            taps_make(&p->ty, s->method, (int)p->crop_h, (int)s->height, area_up))
            goto nomem;
    }
    p->fresh = 1;
    return p;
nomem:
    snprintf(error, error_size, "out of memory for the preprocessing of a %ux%u screen", s->screen_width,
             s->screen_height);
    rk_prep_free(p);
    return NULL;
}

size_t rk_prep_obs_size(const rk_prep *p) { return (size_t)p->s.height * p->s.width * p->ch * p->s.stack; }

int rk_prep_wants_previous(const rk_prep *p) { return p->s.max_pool; }

void rk_prep_restart(rk_prep *p) {
    p->fresh = 1;
    p->have_kept = 0;
}

/* ---- one frame -------------------------------------------------------------------------------- */

/* The cropped frame into `out` (crop_h x crop_w x ch): the rows come from `row_of(y)`, RGB. */
static void load_row_core(rk_prep *p, const rk_core *core, unsigned y) {
    const unsigned w = p->crop_w;
    unsigned have = 0;
    if (core->frame_data && y < core->frame_height && p->s.left < core->frame_width) {
        size_t bpp = core->pixel_format == RK_RETRO_PIXEL_FORMAT_XRGB8888 ? 4 : 2;
        have = core->frame_width - p->s.left < w ? core->frame_width - p->s.left : w;
        const uint8_t *src = (const uint8_t *)core->frame_data + y * core->frame_pitch + p->s.left * bpp;
        if (rk_frame_to_rgb(src, core->frame_pitch, have, 1, core->pixel_format, p->row)) have = 0;
    }
    /* A game that changed resolution: what is off its frame is black, as for the RGB observation. */
    memset(p->row + (size_t)have * 3, 0, (size_t)(w - have) * 3);
}

static void load_row_rgb(rk_prep *p, const uint8_t *rgb, unsigned width, unsigned height, unsigned y) {
    const unsigned w = p->crop_w;
    unsigned have = 0;
    if (y < height && p->s.left < width) {
        have = width - p->s.left < w ? width - p->s.left : w;
        memcpy(p->row, rgb + ((size_t)y * width + p->s.left) * 3, (size_t)have * 3);
    }
    memset(p->row + (size_t)have * 3, 0, (size_t)(w - have) * 3);
}

/* The loaded row into `dst`: RGB as it is, or GrayscaleObservation's luma, summed left to right in
 * doubles and truncated, exactly as numpy computes it. */
static void store_row(const rk_prep *p, uint8_t *dst) {
    const unsigned w = p->crop_w;
    if (!p->s.gray) {
        memcpy(dst, p->row, (size_t)w * 3);
        return;
    }
    const uint8_t *src = p->row;
    for (unsigned x = 0; x < w; x++, src += 3) dst[x] = (uint8_t)(src[0] * 0.2125 + src[1] * 0.7154 + src[2] * 0.0721);
}

static void take_core_frame(rk_prep *p, const rk_core *core, uint8_t *out) {
    size_t stride = (size_t)p->crop_w * p->ch;
    for (unsigned j = 0; j < p->crop_h; j++) {
        load_row_core(p, core, p->s.top + j);
        store_row(p, out + j * stride);
    }
}

void rk_prep_keep(rk_prep *p, const rk_core *core) {
    take_core_frame(p, core, p->kept);
    p->have_kept = 1;
}

/* ---- resize, stack, output ---------------------------------------------------------------------- */

static void resize(rk_prep *p, const uint8_t *src, uint8_t *dst) {
    const unsigned ch = p->ch, in_w = p->crop_w, out_w = p->s.width, out_h = p->s.height;
    const rk_taps *tx = &p->tx, *ty = &p->ty;
    for (unsigned y = 0; y < p->crop_h; y++) {
        const uint8_t *row = src + (size_t)y * in_w * ch;
        float *out = p->pass + (size_t)y * out_w * ch;
        for (unsigned x = 0; x < out_w; x++)
            for (unsigned c = 0; c < ch; c++) {
                float sum = 0;
                for (int t = tx->first[x]; t < tx->first[x + 1]; t++) sum += tx->weight[t] * row[tx->index[t] * ch + c];
                out[x * ch + c] = sum;
            }
    }
    const size_t stride = (size_t)out_w * ch;
    for (unsigned y = 0; y < out_h; y++) {
        uint8_t *out = dst + y * stride;
        for (size_t i = 0; i < stride; i++) {
            float sum = 0;
            for (int t = ty->first[y]; t < ty->first[y + 1]; t++) sum += ty->weight[t] * p->pass[ty->index[t] * stride + i];
            long v = lrintf(sum); /* round half to even, as OpenCV's saturate_cast */
            out[i] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
        }
    }
}

/* The current frame (in p->cur) becomes the stack's newest; the observation is written to dst. */
static void finish(rk_prep *p, uint8_t *dst) {
    const rk_prep_spec *s = &p->s;
    const size_t frame = (size_t)s->height * s->width * p->ch, n = s->stack;
    if (p->have_kept) {
        const size_t all = (size_t)p->crop_h * p->crop_w * p->ch;
        for (size_t i = 0; i < all; i++) p->cur[i] = p->cur[i] > p->kept[i] ? p->cur[i] : p->kept[i];
        p->have_kept = 0;
    }
    p->head = (p->head + 1) % n;
    uint8_t *slot = p->frames + p->head * frame;
    if (s->method == RK_RESIZE_NONE) memcpy(slot, p->cur, frame);
    else resize(p, p->cur, slot);
    if (p->fresh) { /* as FrameStackObservation pads at reset: every slot holds the first frame */
        for (size_t k = 0; k < n; k++)
            if (k != p->head) memcpy(p->frames + k * frame, slot, frame);
        p->fresh = 0;
    }
    const size_t pixels = (size_t)s->height * s->width, ch = p->ch;
    for (size_t k = 0; k < n; k++) { /* oldest first */
        const uint8_t *f = p->frames + ((p->head + 1 + k) % n) * frame;
        if (s->channels_first) {
            for (size_t c = 0; c < ch; c++) {
                uint8_t *plane = dst + (k * ch + c) * pixels;
                for (size_t i = 0; i < pixels; i++) plane[i] = f[i * ch + c];
            }
        } else if (n == 1) {
            memcpy(dst, f, frame);
        } else {
            uint8_t *out = dst + k * ch;
            for (size_t i = 0; i < pixels; i++, out += n * ch) memcpy(out, f + i * ch, ch);
        }
    }
}

void rk_prep_observe(rk_prep *p, const rk_core *core, uint8_t *dst) {
    take_core_frame(p, core, p->cur);
    finish(p, dst);
}

void rk_prep_observe_rgb(rk_prep *p, const uint8_t *rgb, unsigned width, unsigned height, uint8_t *dst) {
    size_t stride = (size_t)p->crop_w * p->ch;
    for (unsigned j = 0; j < p->crop_h; j++) {
        load_row_rgb(p, rgb, width, height, p->s.top + j);
        store_row(p, p->cur + j * stride);
    }
    finish(p, dst);
}
