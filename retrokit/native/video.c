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

static void rows_xrgb8888(const uint8_t *src, size_t pitch, unsigned w, unsigned h, uint8_t *dst) {
    for (unsigned y = 0; y < h; y++) {
        const uint32_t *row = (const uint32_t *)(src + y * pitch);
        uint8_t *out = dst + (size_t)y * w * 3;
        for (unsigned x = 0; x < w; x++) {
            uint32_t p = row[x];
            out[3 * x + 0] = (uint8_t)(p >> 16);
            out[3 * x + 1] = (uint8_t)(p >> 8);
            out[3 * x + 2] = (uint8_t)p;
        }
    }
}

static void rows_rgb565(const uint8_t *src, size_t pitch, unsigned w, unsigned h, uint8_t *dst) {
    for (unsigned y = 0; y < h; y++) {
        const uint16_t *row = (const uint16_t *)(src + y * pitch);
        uint8_t *out = dst + (size_t)y * w * 3;
        for (unsigned x = 0; x < w; x++) {
            unsigned p = row[x];
            out[3 * x + 0] = widen5((p >> 11) & 0x1f);
            out[3 * x + 1] = widen6((p >> 5) & 0x3f);
            out[3 * x + 2] = widen5(p & 0x1f);
        }
    }
}

static void rows_0rgb1555(const uint8_t *src, size_t pitch, unsigned w, unsigned h, uint8_t *dst) {
    for (unsigned y = 0; y < h; y++) {
        const uint16_t *row = (const uint16_t *)(src + y * pitch);
        uint8_t *out = dst + (size_t)y * w * 3;
        for (unsigned x = 0; x < w; x++) {
            unsigned p = row[x];
            out[3 * x + 0] = widen5((p >> 10) & 0x1f);
            out[3 * x + 1] = widen5((p >> 5) & 0x1f);
            out[3 * x + 2] = widen5(p & 0x1f);
        }
    }
}

int rk_frame_to_rgb(const void *frame, size_t pitch, unsigned width, unsigned height, int format, uint8_t *dst) {
    if (!frame) {
        memset(dst, 0, (size_t)width * height * 3);
        return 0;
    }
    switch (format) {
    case RK_RETRO_PIXEL_FORMAT_XRGB8888:
        rows_xrgb8888(frame, pitch, width, height, dst);
        return 0;
    case RK_RETRO_PIXEL_FORMAT_RGB565:
        rows_rgb565(frame, pitch, width, height, dst);
        return 0;
    case RK_RETRO_PIXEL_FORMAT_0RGB1555:
        rows_0rgb1555(frame, pitch, width, height, dst);
        return 0;
    default:
        return -1;
    }
}
