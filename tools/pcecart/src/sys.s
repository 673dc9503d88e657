; What the game needs from the hardware and cc65's library beyond C.
;
; - conio's constructor, which loads cc65's 8x8 font into VRAM at $2000 (tile
;   $200 + ASCII), silences the PSG and sets up the VCE; the game draws its
;   text with those tiles but none of conio's functions.
; - vblank_count: the low byte of the library's tick counter, which its IRQ1
;   handler increments on every vertical-blank interrupt.
; - joypad_read: the pad on port 1, in assembly because cc65's optimiser
;   folds a read of the port after a write to it into the written value.

        .forceimport    initconio
        .importzp       tickcount, tmp1
        .export         _vblank_count, _joypad_read

JOYPAD = $1000

.proc   _vblank_count
        lda     tickcount
        ldx     #0
        rts
.endproc

; Returns the buttons held, active high: bits 0-3 I, II, SELECT, RUN (read
; with SEL low), bits 4-7 up, right, down, left (read with SEL high).
.proc   _joypad_read
        lda     #$01
        sta     JOYPAD
        lda     #$03            ; CLR: a multitap restarts at port 1
        sta     JOYPAD
        lda     #$01
        sta     JOYPAD
        pha                     ; the pad needs a moment after SEL changes
        pla
        nop
        nop
        lda     JOYPAD
        asl     a
        asl     a
        asl     a
        asl     a
        sta     tmp1
        stz     JOYPAD
        pha
        pla
        nop
        nop
        lda     JOYPAD
        and     #$0F
        ora     tmp1
        eor     #$FF
        ldx     #0
        rts
.endproc
