/*
 * Converting the core's last frame to packed RGB, on request only.
 */
#include "video.h"

#include <string.h>

/* 5- and 6-bit channels widen to 8 bits by a plain shift, as Gym Retro and
 * stable-retro do, so observations are identical to theirs (full intensity
 * is 248 or 252, not 255). */
static inline uint8_t widen5(unsigned v) { return (uint8_t)(v << 3); }
static inline uint8_t widen6(unsigned v) { return (uint8_t)(v << 2); }

/* The row loops vectorise well with SSSE3 byte shuffles (x86-64-v2: about
 * 5x faster). GCC builds a baseline and a v2 version of each and picks one
 * when the module loads, so the module still runs on any x86-64. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define RK_VECTORISED __attribute__((target_clones("default", "arch=x86-64-v2")))
#else
#define RK_VECTORISED
#endif

/* One row loop per pixel format: each `type` pixel p becomes the bytes r, g, b. */
#define RK_ROWS(name, type, r, g, b)                                                                            \
    RK_VECTORISED static void name(const uint8_t *restrict src, size_t pitch, unsigned w, unsigned h,           \
                                   uint8_t *restrict dst) {                                                     \
        for (size_t y = 0; y < h; y++) {                                                                        \
            const type *restrict row = (const type *)(src + y * pitch);                                         \
            for (size_t x = 0; x < w; x++, dst += 3) {                                                          \
                unsigned p = row[x];                                                                            \
                dst[0] = (uint8_t)(r);                                                                          \
                dst[1] = (uint8_t)(g);                                                                          \
                dst[2] = (uint8_t)(b);                                                                          \
            }                                                                                                   \
        }                                                                                                       \
    }

RK_ROWS(rows_xrgb8888, uint32_t, p >> 16, p >> 8, p)
RK_ROWS(rows_rgb565, uint16_t, widen5((p >> 11) & 0x1f), widen6((p >> 5) & 0x3f), widen5(p & 0x1f))
RK_ROWS(rows_0rgb1555, uint16_t, widen5((p >> 10) & 0x1f), widen5((p >> 5) & 0x1f), widen5(p & 0x1f))

int rk_frame_to_rgb(const void *frame, size_t pitch, unsigned width, unsigned height, int format, uint8_t *dst) {
    if (!frame) {
        memset(dst, 0, (size_t)width * height * 3);
        return 0;
    }
    switch (format) {
    case RK_RETRO_PIXEL_FORMAT_XRGB8888: rows_xrgb8888(frame, pitch, width, height, dst); return 0;
    case RK_RETRO_PIXEL_FORMAT_RGB565: rows_rgb565(frame, pitch, width, height, dst); return 0;
    case RK_RETRO_PIXEL_FORMAT_0RGB1555: rows_0rgb1555(frame, pitch, width, height, dst); return 0;
    default: return -1;
    }
}
