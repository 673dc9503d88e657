;; Trekker's start-up code and cartridge header (sdasgb syntax).
;;
;; 0x0000-0x014F: restart and interrupt vectors, then the header the boot ROM
;; reads: entry point, the Nintendo logo (the boot ROM compares it with its
;; own copy and locks up on a mismatch), title, CGB flag, cartridge type and
;; sizes.  The header checksum (0x14D) and the global checksum (0x14E-0x14F)
;; are left 0 here and filled in by fixrom.py.  The CGB flag at 0x143 is the
;; link-time symbol CGB_FLAG (0x80 for the Game Boy Color build, 0x00 for the
;; Game Boy build; see the Makefile).

        .module crt0
        .globl  _main
        .globl  CGB_FLAG
        .globl  l__INITIALIZER
        .globl  s__INITIALIZER
        .globl  s__INITIALIZED

ADDR_HW_CGB     = 0xC003
ADDR_VBLANKS    = 0xC012
ADDR_CRASH      = 0xC01A
ADDR_VBLANK_FLAG = 0xC01B
OAM_SHADOW_HI   = 0xC2      ; the sprite table the main loop fills, 0xC200-0xC29F
HRAM_DMA        = 0xFF80    ; where the OAM DMA routine runs from

        .area   _HEADER (ABS)

        ;; rst 0x38 is opcode 0xFF, what erased ROM holds: a jump into
        ;; nowhere lands here, records it and stops.
        .org    0x38
        ld      a, #1
        ld      (ADDR_CRASH), a
        di
1$:     jr      1$

        .org    0x40            ; VBlank
        jp      vblank_isr
        .org    0x48            ; LCD STAT
        reti
        .org    0x50            ; timer
        reti
        .org    0x58            ; serial
        reti
        .org    0x60            ; joypad
        reti

        .org    0x100
        nop
        jp      boot
        ;; 0x104-0x133: the Nintendo logo bitmap (Pan Docs, "The Cartridge Header").
        .db     0xCE, 0xED, 0x66, 0x66, 0xCC, 0x0D, 0x00, 0x0B, 0x03, 0x73, 0x00, 0x83, 0x00, 0x0C, 0x00, 0x0D
        .db     0x00, 0x08, 0x11, 0x1F, 0x88, 0x89, 0x00, 0x0E, 0xDC, 0xCC, 0x6E, 0xE6, 0xDD, 0xDD, 0xD9, 0x99
        .db     0xBB, 0xBB, 0x67, 0x63, 0x6E, 0x0E, 0xEC, 0xCC, 0xDD, 0xDC, 0x99, 0x9F, 0xBB, 0xB9, 0x33, 0x3E
        .ascii  "TREKKER"       ; 0x134: the title, zero-padded to 0x143
        .db     0, 0, 0, 0, 0, 0, 0, 0
        .db     CGB_FLAG        ; 0x143
        .ascii  "00"            ; 0x144: new licensee code: none
        .db     0x00            ; 0x146: no Super Game Boy functions
        .db     0x00            ; 0x147: ROM only, no mapper
        .db     0x00            ; 0x148: 32 KiB
        .db     0x00            ; 0x149: no cartridge RAM
        .db     0x01            ; 0x14A: sold outside Japan
        .db     0x33            ; 0x14B: the licensee is the new code at 0x144
        .db     0x00            ; 0x14C: version 0
        .db     0x00            ; 0x14D: header checksum (fixrom.py)
        .db     0x00, 0x00      ; 0x14E: global checksum, big-endian (fixrom.py)

        .org    0x150
boot:
        di
        ld      sp, #0xE000
        ld      b, a            ; A = 0x11 after a Game Boy Color's boot ROM
        ;; Clear work RAM 0xC001-0xDFFF.  0xC000, the level select, is kept
        ;; so a tool may write it before the first frame.
        ld      hl, #0xC001
        ld      de, #0x1FFF
2$:     xor     a
        ld      (hl+), a
        dec     de
        ld      a, d
        or      e
        jr      nz, 2$
        ld      a, b
        cp      #0x11
        ld      a, #0
        jr      nz, 3$
        inc     a
3$:     ld      (ADDR_HW_CGB), a
        ;; The OAM DMA routine must run from HRAM (the CPU sees only HRAM
        ;; during the transfer).
        ld      hl, #HRAM_DMA
        ld      de, #dma_routine
        ld      c, #(dma_end - dma_routine)
4$:     ld      a, (de)
        inc     de
        ld      (hl+), a
        dec     c
        jr      nz, 4$
        ;; Initialised C variables: copy their initial values into RAM.
        ld      de, #s__INITIALIZER
        ld      hl, #s__INITIALIZED
        ld      bc, #l__INITIALIZER
5$:     ld      a, b
        or      c
        jr      z, 6$
        ld      a, (de)
        inc     de
        ld      (hl+), a
        dec     bc
        jr      5$
6$:     call    gsinit
        call    _main
7$:     jr      7$

;; Copied to HRAM at boot: start the DMA from the shadow table and wait the
;; 160 microseconds it takes.
dma_routine:
        ld      a, #OAM_SHADOW_HI
        ldh     (0x46), a
        ld      a, #40
8$:     dec     a
        jr      nz, 8$
        ret
dma_end:

vblank_isr:
        push    af
        push    hl
        ld      hl, #ADDR_VBLANKS
        inc     (hl)
        jr      nz, 9$
        inc     hl
        inc     (hl)
9$:     ld      a, #1
        ld      (ADDR_VBLANK_FLAG), a
        pop     hl
        pop     af
        reti

        .area   _CODE
;; void wait_vblank(void): sleep until the next VBlank interrupt.
_wait_vblank::
        xor     a
        ld      (ADDR_VBLANK_FLAG), a
10$:    halt
        nop
        ld      a, (ADDR_VBLANK_FLAG)
        or      a
        jr      z, 10$
        ret

;; void oam_dma(void): copy the shadow sprite table into OAM (call in VBlank).
_oam_dma::
        jp      HRAM_DMA

        .area   _INITIALIZER
        .area   _GSINIT
gsinit:
        .area   _GSFINAL
        ret
        .area   _DATA
        .area   _INITIALIZED
        .area   _BSEG
        .area   _BSS
        .area   _HEAP
