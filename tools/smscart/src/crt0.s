; Hopper's start-up code for the Z80 of the Master System and Game Gear.
;
; 0x0000: reset; 0x0038: the VDP's frame interrupt (mode 1); 0x0066: the NMI
; of the Master System's PAUSE button (the Game Gear has none: its START is a
; port bit). RAM addresses repeat src/ram.h (ADDR_VBLANKS, ADDR_PAUSE).

        .module crt0
        .globl  _main
        .globl  l__INITIALIZER, s__INITIALIZER, s__INITIALIZED

VBLANKS = 0xC010
PAUSE   = 0xC011
RAM_KEEP_END = 0xC001           ; 0xC000 (the level select) survives the clear
STACK   = 0xDFF0

        .area   _HEADER (ABS)
        .org    0x0000
        di
        im      1
        ld      sp, #STACK
        jp      boot

        .org    0x0038
        push    af
        in      a, (0xBF)       ; reading the status acknowledges the interrupt
        ld      a, (VBLANKS)
        inc     a
        ld      (VBLANKS), a
        pop     af
        ei
        reti

        .org    0x0066
        push    af
        ld      a, #1
        ld      (PAUSE), a
        pop     af
        retn

boot:
        ; Clear work RAM except the level select, so a tool may poke the level
        ; before the first frame.
        ld      hl, #RAM_KEEP_END
        ld      de, #RAM_KEEP_END + 1
        ld      bc, #STACK - RAM_KEEP_END - 1
        ld      (hl), #0
        ldir
        ; Copy initialised data, if the compiler made any.
        ld      bc, #l__INITIALIZER
        ld      a, b
        or      a, c
        jr      z, 1$
        ld      de, #s__INITIALIZED
        ld      hl, #s__INITIALIZER
        ldir
1$:     call    _main
2$:     halt
        jr      2$

        ; The order of the compiler's areas: code and constants in ROM, then RAM.
        .area   _CODE
        .area   _INITIALIZER
        .area   _GSINIT
        .area   _GSFINAL
        .area   _DATA
        .area   _INITIALIZED
        .area   _BSS
        .area   _HEAP
