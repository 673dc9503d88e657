; Hopper's boot code, iNES header, NMI handler and PPU write queue.
;
; The addresses below repeat src/ram.h (tests/test_nescart.py checks that
; they agree): ca65 cannot read a C header.

.export __STARTUP__ : absolute = 1   ; keeps the library's crt0 out of the link
.export _queue_flush
.import _main, copydata
.import __STACK_START__, __STACKSIZE__
.importzp sp

ADDR_WORLD      = $0040
ADDR_STAGE      = $0041
ADDR_VBLANKS    = $0052
ADDR_NMI_READY  = $005C
ADDR_PPU_CTRL   = $005D
ADDR_PPU_MASK   = $005E
ADDR_SCROLL_X   = $005F
ADDR_QUEUE_LEN  = $0062
ADDR_OAM        = $0200
ADDR_QUEUE      = $0500

PPUCTRL   = $2000
PPUMASK   = $2001
PPUSTATUS = $2002
OAMADDR   = $2003
PPUSCROLL = $2005
PPUADDR   = $2006
PPUDATA   = $2007
DMC_FREQ  = $4010
OAMDMA    = $4014
APU_FRAME = $4017

; iNES: 2 x 16 KiB PRG, 1 x 8 KiB CHR, mapper 0 (NROM), vertical mirroring
; (the two nametables side by side, for horizontal scrolling).
.segment "HEADER"
    .byte "NES", $1A, 2, 1, $01, $00
    .res 8, 0

.segment "STARTUP"
reset:
    sei
    cld
    ldx #$40
    stx APU_FRAME           ; no APU frame interrupt
    ldx #$FF
    txs
    inx
    stx PPUCTRL             ; no NMI until the game asks
    stx PPUMASK             ; rendering off
    stx DMC_FREQ            ; no DMC interrupt
    bit PPUSTATUS
@vblank1:
    bit PPUSTATUS
    bpl @vblank1
    ; Clear RAM while the PPU warms up, except the level select (world and
    ; stage at $0040-$0041), so a tool may write it before the first frame.
    lda #0
    tax
@clear:
    cpx #<ADDR_WORLD
    bcc @zero
    cpx #<(ADDR_STAGE + 1)
    bcc @keep
@zero:
    sta $0000,x
@keep:
    sta $0100,x
    sta $0200,x
    sta $0300,x
    sta $0400,x
    sta $0500,x
    sta $0600,x
    sta $0700,x
    inx
    bne @clear
    lda #$FF                ; hide every sprite
@hide:
    sta ADDR_OAM,x
    inx
    bne @hide
@vblank2:
    bit PPUSTATUS
    bpl @vblank2
    lda #<(__STACK_START__ + __STACKSIZE__)
    sta sp
    lda #>(__STACK_START__ + __STACKSIZE__)
    sta sp+1
    jsr copydata
    jsr _main
@halt:
    jmp @halt

; The NMI counts vertical blanks; when the main loop has a frame ready it
; copies the sprite table, empties the PPU write queue and sets the scroll.
nmi:
    pha
    txa
    pha
    tya
    pha
    inc ADDR_VBLANKS
    bne @counted
    inc ADDR_VBLANKS+1
@counted:
    lda ADDR_NMI_READY
    beq @done
    lda #0
    sta OAMADDR
    lda #>ADDR_OAM
    sta OAMDMA
    jsr _queue_flush
    lda ADDR_PPU_CTRL
    sta PPUCTRL
    lda ADDR_SCROLL_X
    sta PPUSCROLL
    lda #0
    sta PPUSCROLL
    lda ADDR_PPU_MASK
    sta PPUMASK
    lda #0
    sta ADDR_NMI_READY
@done:
    pla
    tay
    pla
    tax
    pla
irq:
    rti

; Write the queue to the PPU and empty it.  Entries are: PPU address high
; byte (bit 7 set: step down a column, by 32), low byte, count, data; a zero
; high byte ends the queue.  Called by the NMI handler, and from C while
; rendering is off.
_queue_flush:
    ldx #0
@entry:
    lda ADDR_QUEUE,x
    beq @end
    tay
    lda ADDR_PPU_CTRL
    and #$FB                ; increment by 1...
    cpy #$80
    bcc @step
    ora #$04                ; ...or by 32, down a column
@step:
    sta PPUCTRL
    bit PPUSTATUS
    tya
    and #$3F
    sta PPUADDR
    lda ADDR_QUEUE+1,x
    sta PPUADDR
    ldy ADDR_QUEUE+2,x
    inx
    inx
    inx
@copy:
    lda ADDR_QUEUE,x
    sta PPUDATA
    inx
    dey
    bne @copy
    beq @entry
@end:
    lda #0
    sta ADDR_QUEUE
    sta ADDR_QUEUE_LEN
    rts

.segment "VECTORS"
    .word nmi, reset, irq
