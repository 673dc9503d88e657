/* The PPU write queue, text, pads, random numbers and frame pacing. */
#include <string.h>

#include "game.h"

#define PPUCTRL BYTE(0x2000)
#define PPUMASK BYTE(0x2001)
#define PPUSTATUS BYTE(0x2002)
#define PPUADDR BYTE(0x2006)
#define PPUDATA BYTE(0x2007)
#define JOY1 0x4016
#define JOY2 0x4017

#define CTRL_NMI 0x80
#define MASK_SHOW 0x1E /* background and sprites, left column included */

static const unsigned char palettes[32] = {
    0x21, 0x1A, 0x17, 0x30, 0x21, 0x1A, 0x17, 0x30, /* sky, grass, dirt, white */
    0x21, 0x1A, 0x17, 0x30, 0x21, 0x1A, 0x17, 0x30,
    0x21, 0x12, 0x36, 0x30, 0x21, 0x27, 0x36, 0x30, /* player 1 blue, player 2 orange */
    0x21, 0x14, 0x0F, 0x30, 0x21, 0x28, 0x38, 0x30, /* crawler purple, coin gold */
};

/* Start a queue entry of `count` bytes at PPU address `addr` (down a column
 * if `down`); the caller fills the returned bytes.  A full queue is first
 * written out by waiting a frame, so nothing is ever dropped. */
unsigned char *queue_entry(unsigned addr, unsigned char count, unsigned char down)
{
    unsigned char *entry;
    if (queue_len + 4 + count > QUEUE_SIZE) {
        if (ppu_mask)
            wait_frame();
        else
            queue_flush();
    }
    entry = queue + queue_len;
    entry[0] = (unsigned char)(addr >> 8) | (down ? 0x80 : 0);
    entry[1] = (unsigned char)addr;
    entry[2] = count;
    queue_len += 3 + count;
    queue[queue_len] = 0;
    return entry + 3;
}

/* Hand the frame to the NMI handler and wait until it has taken it. */
void wait_frame(void)
{
    nmi_ready = 1;
    while (nmi_ready) {
    }
}

void ppu_off(void)
{
    ppu_mask = 0;
    wait_frame();
}

void ppu_on(void)
{
    ppu_mask = MASK_SHOW;
    ppu_ctrl = CTRL_NMI | ((camera_x >> 8) & 1);
    scroll_x = (unsigned char)camera_x;
    wait_frame();
}

void clear_nametables(void)
{
    unsigned i;
    PPUCTRL = CTRL_NMI;
    (void)PPUSTATUS;
    PPUADDR = 0x20;
    PPUADDR = 0x00;
    for (i = 0; i < 0x800; ++i)
        PPUDATA = 0;
}

void ppu_init(void)
{
    ppu_ctrl = CTRL_NMI;
    PPUCTRL = CTRL_NMI;
    memcpy(queue_entry(0x3F00, 32, 0), palettes, 32);
    queue_flush();
    clear_nametables();
}

void text(unsigned addr, const char *s)
{
    unsigned char n = (unsigned char)strlen(s);
    memcpy(queue_entry(addr, n, 0), s, n);
}

/* Text at a screen column and row while scrolled: one entry a character,
 * since the line may cross from one nametable into the other. */
void screen_text(unsigned char column, unsigned char row, const char *s)
{
    unsigned tc = (camera_x >> 3) + column;
    for (; *s; ++s, ++tc)
        *queue_entry(0x2000 + ((tc & 32) ? 0x400 : 0) + row * 32 + (tc & 31), 1, 0) = *s;
}

static unsigned char read_pad(unsigned port)
{
    unsigned char i, value = 0;
    for (i = 0; i < 8; ++i)
        value = (value << 1) | (BYTE(port) & 1);
    return value;
}

/* Read both pads, count the frame and stir the random state with them. */
void read_pads(void)
{
    unsigned char held1, held2;
    BYTE(JOY1) = 1;
    BYTE(JOY1) = 0;
    held1 = read_pad(JOY1);
    held2 = read_pad(JOY2);
    pad1_new = held1 & ~pad1;
    pad2_new = held2 & ~pad2;
    pad1 = held1;
    pad2 = held2;
    if (++frame_lo == 0)
        ++frame_hi;
    rng ^= (held1 | ((unsigned)held2 << 8)) ^ frame_lo;
    rnd();
}

/* One step of a 16-bit xorshift (shifts 7, 9, 8): shifts, where a multiply
 * would cost the 6502 a frame's spare time; 0 would stay 0, so it becomes 1. */
unsigned char rnd(void)
{
    unsigned x = rng;
    if (!x)
        x = 1;
    x ^= x << 7;
    x ^= x >> 9;
    x ^= x << 8;
    rng = x;
    return (unsigned char)x;
}
