/*
 * Dasher start-up: the 68000 vector table, the cartridge header, the boot
 * code that runs before C, and the interrupt / exception handlers.
 *
 * The linker script places section .text.boot at ROM address 0.
 * Registers are written with the % prefix (GNU as, Motorola syntax).
 */
#include "../src/ram.h"

    .section .text.boot,"ax"
    .globl _start

/* ---- 0x000: vector table (64 long words) --------------------------------- */
vectors:
    .long 0x01000000            /* 0: initial SSP; first push lands at 0xFFFFFC */
    .long _start                /* 1: initial PC */
    .long exc_bus               /* 2: bus error */
    .long exc_address           /* 3: address error (odd word access) */
    .long exc_illegal           /* 4: illegal instruction */
    .long exc_zero_divide       /* 5: divide by zero */
    .rept 18                    /* 6-23: CHK, TRAPV, privilege, trace, line A/F, reserved */
    .long exc_other
    .endr
    .long int_ignore            /* 24: spurious interrupt */
    .long int_ignore            /* 25: level 1 */
    .long int_ignore            /* 26: level 2: external (pad TH pin) */
    .long int_ignore            /* 27: level 3 */
    .long int_ignore            /* 28: level 4: HBlank */
    .long int_ignore            /* 29: level 5 */
    .long int_vblank            /* 30: level 6: VBlank */
    .long int_ignore            /* 31: level 7 */
    .rept 32                    /* 32-47: TRAP #n; 48-63: reserved */
    .long exc_other
    .endr

/* ---- 0x100: cartridge header ----------------------------------------------
 * fixrom.py fills the checksum (0x18E) and the ROM end address (0x1A4) after
 * linking; everything else is fixed here, so the build is reproducible. */
    .org 0x100
    .ascii "SEGA MEGA DRIVE "                       /* system: TMSS checks "SEGA" */
    .org 0x110
    .ascii "(C)RTKT 2025.JAN"                       /* copyright and fixed date */
    .org 0x120
    .ascii "DASHER"                                 /* domestic name, 48 bytes */
    .org 0x150, 0x20
    .ascii "DASHER"                                 /* overseas name, 48 bytes */
    .org 0x180, 0x20
    .ascii "GM 00000000-01"                         /* type, serial, revision */
    .word 0x0000                                    /* 0x18E: checksum (fixrom.py) */
    .ascii "J"                                      /* 0x190: I/O: 3-button pad */
    .org 0x1A0, 0x20
    .long 0x00000000                                /* ROM start */
    .long 0x00000000                                /* 0x1A4: ROM end (fixrom.py) */
    .long 0x00FF0000                                /* RAM start */
    .long 0x00FFFFFF                                /* RAM end */
    .ascii "            "                           /* 0x1B0: no backup RAM */
    .ascii "            "                           /* 0x1BC: no modem */
    .ascii "RETROKIT TEST CARTRIDGE"                /* 0x1C8: notes, 40 bytes */
    .org 0x1F0, 0x20
    .ascii "JUE"                                    /* regions: Japan, USA, Europe */
    .org 0x200, 0x20

/* ---- 0x200: boot --------------------------------------------------------- */
_start:
    move.w  #0x2700, %sr            /* supervisor mode, all interrupts masked */

    /* TMSS: consoles whose version register has a non-zero low nibble
     * lock the VDP until "SEGA" is written to 0xA14000. */
    move.b  0xA10001, %d7           /* d7 = raw version register */
    moveq   #0, %d6                 /* d6 = handshake done? */
    move.b  %d7, %d0
    andi.b  #0x0F, %d0
    beq.s   1f
    move.l  #0x53454741, 0xA14000   /* "SEGA" */
    moveq   #1, %d6
1:
    /* Clear work RAM, except the level-select bytes zone and act
     * (0xFF0000-0xFF0001): a tool may write them before the first frame
     * and the title screen honours them.  Clears 0xFF0002-0xFFFFFF. */
    move.w  #0, ADDR_GAME_MODE      /* game_mode and level_done */
    lea     RAM_BASE+4, %a0
    move.w  #(0x10000-4)/4-1, %d0
2:  clr.l   (%a0)+
    dbra    %d0, 2b
    move.b  %d7, ADDR_HW_VERSION
    move.b  %d6, ADDR_TMSS

    /* Copy initialised data from ROM to RAM (.bss was cleared above). */
    lea     _data_load, %a0
    lea     _data_start, %a1
    move.l  #_data_end, %d0
    sub.l   %a1, %d0
    lsr.l   #1, %d0
    bra.s   4f
3:  move.w  (%a0)+, (%a1)+
4:  dbra    %d0, 3b

    jsr     game_main
5:  bra.s   5b

/* ---- interrupts ---------------------------------------------------------- */
int_vblank:
    addq.w  #1, ADDR_VBLANKS        /* the main loop waits for this to change */
    rte

int_ignore:
    rte

/* ---- CPU exceptions: record the vector number, paint the backdrop red,
 * stop.  Tests check that ADDR_CRASH stays 0. */
exc_bus:
    move.b  #2, ADDR_CRASH
    bra.s   crashed
exc_address:
    move.b  #3, ADDR_CRASH
    bra.s   crashed
exc_illegal:
    move.b  #4, ADDR_CRASH
    bra.s   crashed
exc_zero_divide:
    move.b  #5, ADDR_CRASH
    bra.s   crashed
exc_other:
    move.b  #0xFF, ADDR_CRASH
crashed:
    move.w  #0x2700, %sr
    move.l  #0xC0000000, 0xC00004   /* CRAM write, address 0 */
    move.w  #0x000E, 0xC00000       /* backdrop colour 0 = red */
6:  bra.s   6b
