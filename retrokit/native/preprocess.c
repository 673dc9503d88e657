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
 * a vertical pass into floats and a horizontal pass into bytes, rounded to
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
    float *pass;              /* height x crop_w x ch: the vertical pass */
    uint8_t *gray16;          /* the luma of every 16-bit pixel, for gray16_format */
    int gray16_format;
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
    free(p->gray16);
    free(p->frames);
    taps_free(&p->tx);
    taps_free(&p->ty);
    free(p);
}

rk_prep *rk_prep_new(const rk_prep_spec *s, char *error, size_t error_size) {
    const unsigned limit = 1u << 14; /* no console screen, nor a sensible observation, is larger */
    if (!s->screen_height || !s->screen_width || s->screen_height > limit || s->screen_width > limit ||
        s->top > limit || s->bottom > limit || s->left > limit || s->right > limit || /* sums cannot wrap */
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
        p->pass = malloc((size_t)s->height * p->crop_w * p->ch * sizeof(float));
        if (!p->pass || taps_make(&p->tx, s->method, (int)p->crop_w, (int)s->width, area_up) ||
            taps_make(&p->ty, s->method, (int)p->crop_h, (int)s->height, area_up))
            goto nomem;
    }
    p->fresh = 1;
    p->gray16_format = -1;
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

/* Row y of the core's frame, cropped, into p->row as RGB. */
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
static uint8_t luma(const uint8_t *rgb);

static void store_row(const rk_prep *p, uint8_t *dst) {
    const unsigned w = p->crop_w;
    if (!p->s.gray) {
        memcpy(dst, p->row, (size_t)w * 3);
        return;
    }
    for (unsigned x = 0; x < w; x++) dst[x] = luma(p->row + 3 * x);
}

static uint8_t luma(const uint8_t *rgb) { return (uint8_t)(rgb[0] * 0.2125 + rgb[1] * 0.7154 + rgb[2] * 0.0721); }

/* For a 16-bit pixel format, the luma of each of its 65536 pixels, made once through the same RGB
 * conversion as the screen's (video.c), so a gray frame is one table lookup per pixel; NULL for
 * another format (or short of memory: then the rows go through RGB). */
static const uint8_t *gray_table(rk_prep *p, int format) {
    if (format != RK_RETRO_PIXEL_FORMAT_RGB565 && format != RK_RETRO_PIXEL_FORMAT_0RGB1555) return NULL;
    if (p->gray16_format == format) return p->gray16;
    uint16_t *all = malloc(65536 * sizeof(uint16_t));
    uint8_t *rgb = malloc(65536 * 3);
    if (!p->gray16) p->gray16 = malloc(65536);
    int ok = all && rgb && p->gray16;
    if (ok) {
        for (unsigned v = 0; v < 65536; v++) all[v] = (uint16_t)v;
        ok = rk_frame_to_rgb(all, 65536 * sizeof(uint16_t), 65536, 1, format, rgb) == 0;
    }
    for (unsigned v = 0; ok && v < 65536; v++) p->gray16[v] = luma(rgb + 3 * v);
    free(all);
    free(rgb);
    p->gray16_format = ok ? format : -1;
    return ok ? p->gray16 : NULL;
}

static void take_core_frame(rk_prep *p, const rk_core *core, uint8_t *out) {
    const size_t stride = (size_t)p->crop_w * p->ch;
    const uint8_t *table = p->s.gray && core->frame_data ? gray_table(p, core->pixel_format) : NULL;
    for (unsigned j = 0; j < p->crop_h; j++) {
        const unsigned y = p->s.top + j;
        uint8_t *dst = out + j * stride;
        if (table) {
            unsigned have = 0;
            if (y < core->frame_height && p->s.left < core->frame_width) {
                have = core->frame_width - p->s.left < p->crop_w ? core->frame_width - p->s.left : p->crop_w;
                const uint16_t *src = (const uint16_t *)((const uint8_t *)core->frame_data + y * core->frame_pitch) +
                                      p->s.left;
                for (unsigned x = 0; x < have; x++) dst[x] = table[src[x]];
            }
            memset(dst + have, 0, p->crop_w - have);
            continue;
        }
        load_row_core(p, core, y);
        store_row(p, dst);
    }
}

void rk_prep_keep(rk_prep *p, const rk_core *core) {
    take_core_frame(p, core, p->kept);
    p->have_kept = 1;
}

/* ---- resize, stack, output ---------------------------------------------------------------------- */

/* Rows first, over contiguous bytes (the compiler vectorises it), then columns, on the fewer rows left.
 * OpenCV sums columns first: the same weights in another order, so a pixel may round the other way. */
static void resize(rk_prep *p, const uint8_t *src, uint8_t *dst) {
    const unsigned ch = p->ch, out_w = p->s.width, out_h = p->s.height;
    const size_t in_stride = (size_t)p->crop_w * ch;
    const rk_taps *tx = &p->tx, *ty = &p->ty;
    for (unsigned y = 0; y < out_h; y++) {
        float *restrict acc = p->pass + y * in_stride;
        memset(acc, 0, in_stride * sizeof(float));
        for (int t = ty->first[y]; t < ty->first[y + 1]; t++) {
            const float w = ty->weight[t];
            const uint8_t *restrict row = src + (size_t)ty->index[t] * in_stride;
            for (size_t i = 0; i < in_stride; i++) acc[i] += w * row[i];
        }
    }
    for (unsigned y = 0; y < out_h; y++) {
        const float *row = p->pass + y * in_stride;
        uint8_t *out = dst + (size_t)y * out_w * ch;
        for (unsigned x = 0; x < out_w; x++)
            for (unsigned c = 0; c < ch; c++) {
                float sum = 0;
                for (int t = tx->first[x]; t < tx->first[x + 1]; t++) sum += tx->weight[t] * row[tx->index[t] * ch + c];
                long v = lrintf(sum); /* round half to even, as OpenCV's saturate_cast */
                out[x * ch + c] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
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
        } else { /* interleaved: each pixel's channels of every frame side by side */
            uint8_t *out = dst + k * ch;
            const size_t step = n * ch;
            for (size_t i = 0; i < pixels; i++, out += step, f += ch)
                for (size_t c = 0; c < ch; c++) out[c] = f[c];
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
