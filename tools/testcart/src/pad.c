/*
 * Control pads, read through the TH protocol.
 *
 * Each port's data register shows six pad lines.  Pin TH (bit 6) is an
 * output we drive; the pad multiplexes its buttons on it:
 *   TH = 1:  bit 0 Up, 1 Down, 2 Left, 3 Right, 4 B, 5 C
 *   TH = 0:  bit 0 Up, 1 Down, 4 A, 5 Start   (bits 2-3 read 0)
 * Lines are active low.  One TH cycle per frame also keeps a 6-button pad in
 * its 3-button mode (it switches only after three quick cycles).
 */
#include "pad.h"
#include "ram.h"

void pad_init(void)
{
    IO_CTRL1 = 0x40; /* TH is an output, the other pins inputs */
    IO_CTRL2 = 0x40;
    IO_DATA1 = 0x40; /* rest with TH high */
    IO_DATA2 = 0x40;
}

/* Returns PAD_* bits, active high. */
static u8 read_port(volatile u8 *data)
{
    u8 th_high, th_low;
    *data = 0x40;
    __asm__ volatile("nop\n\tnop"); /* let the pad's multiplexer settle */
    th_high = *data;
    *data = 0x00;
    __asm__ volatile("nop\n\tnop");
    th_low = *data;
    *data = 0x40;
    return (u8)~((th_high & 0x3F) | ((th_low & 0x30) << 2));
}

void pad_read_all(void)
{
    u8 now;
    now = read_port(&IO_DATA1);
    RAM.pad_new[0] = now & ~RAM.pad[0];
    RAM.pad[0] = now;
    now = read_port(&IO_DATA2);
    RAM.pad_new[1] = now & ~RAM.pad[1];
    RAM.pad[1] = now;
}
