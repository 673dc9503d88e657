; Skipper: retrokit's SNES cartridge, a tiny two-player run-and-jump game.
; 65816 assembly for ca65 (.p816), linked by ld65 with snes.cfg into one
; 32 KiB LoROM bank. See README.md for the game, controls and RAM map.
;
; Conventions: the direct page and the data bank stay 0, so work RAM's first
; 8 KiB and the hardware registers are plain absolute addresses. Every routine
; is entered and left with A 8-bit and X/Y 16-bit (A8 / I16), switching A to
; 16 bits inside where it handles words.

.p816
.include "ram.inc"

.macro A8
    sep #$20
    .a8
.endmacro
.macro A16
    rep #$20
    .a16
.endmacro

; Pad bits as the auto-joypad registers JOY1L/H ($4218) give them.
PAD_START = $1000
PAD_LR    = $0300        ; LEFT $0200, RIGHT $0100
PAD_JUMP  = $C0C0        ; B, Y, A, X: any face button jumps

GRAVITY   = $0040        ; 1/4 pixel a frame, per frame
JUMP_VY   = $FC00        ; -4 pixels a frame: 32 pixels high, 32 frames in the air
MAX_VY    = $0600
SPEED     = 2            ; pixels a frame
FALL_Y    = 232          ; feet this low: fell into a pit
PIT_TOP   = $0200        ; "ground top" of a pit: below everything

BG1_MAP   = $1000        ; VRAM word addresses: the level (64x32 tiles)
BG2_MAP   = $1800        ; the HUD and text (32x32), over the level
OBJ_TILES = $4000        ; sprite tiles

goal_column = ADDR_TEMP + 2   ; the column of the goal pole (set per level)
temp2       = ADDR_TEMP + 4
temp3       = ADDR_TEMP + 6

.segment "CODE"

; ---------------------------------------------------------------- boot
reset:
    sei
    clc
    xce                     ; native mode
    rep #$38                ; 16-bit A/X/Y, binary arithmetic
    .a16
    .i16
    ldx #$1FFF
    txs
    lda #$0000
    tcd                     ; direct page 0 (the data bank is 0 after reset)
    A8
    lda #$80
    sta $2100               ; forced blank
    stz $4200               ; no NMI until the screen is ready

    ; Clear all 128 KiB of work RAM by DMA from a zero byte, but keep the
    ; level select, so a tool may poke it before the first frame.
    ldy level
    stz $2181
    stz $2182
    stz $2183
    lda #$08                ; fixed source, one register
    sta $4300
    lda #$80                ; $2180, the work RAM port
    sta $4301
    ldx #.loword(zero_byte)
    stx $4302
    stz $4304
    ldx #0
    stx $4305               ; 0 = 65536 bytes
    lda #1
    sta $420B
    stx $4305
    sta $420B               ; the second 64 KiB
    tya
    sta level

    ; Clear VRAM (64 KiB) the same way, through $2118/$2119.
    lda #$80
    sta $2115
    stx $2116
    lda #$09                ; fixed source, two registers
    sta $4300
    lda #$18
    sta $4301
    stx $4305
    lda #1
    sta $420B

    jsr init_ppu
    jsr load_palettes
    ldx #0                  ; background tiles at VRAM 0, sprite tiles at OBJ_TILES
    stx $2116
    ldx #.loword(bg_tiles)
    ldy #sprite_tiles - bg_tiles
    jsr dma_vram
    ldx #OBJ_TILES
    stx $2116
    ldx #.loword(sprite_tiles)
    ldy #32 * 32
    jsr dma_vram
    jsr enter_title
    lda #$81                ; NMI on, auto-joypad read on
    sta $4200

; ---------------------------------------------------------------- main loop
; One pass a frame: wait for the NMI, update VRAM while in VBlank, read the
; pads, then run the game mode.
main_loop:
    jsr wait_vblank
    jsr vblank_work
    jsr read_pads
    A16
    inc frame
    bne :+
    inc frame + 2
:   lda rng                 ; stir the random state: rng * 5 + 0x3711, xored with the frame and pads
    asl
    asl
    clc
    adc rng
    adc #$3711
    eor frame
    eor pad1
    eor pad2
    sta rng
    lda game_mode
    and #$0003
    asl
    tax
    A8
    jsr (mode_table, x)
    jsr build_oam
    bra main_loop

mode_table:
    .word do_title, do_play, do_clear, do_gameover

nmi:
    php
    A16
    pha
    inc vblanks
    lda $4210               ; acknowledge the NMI
    pla
    plp
    rti

ignore:
    rti

wait_vblank:
    A16
    lda vblanks
:   cmp vblanks
    beq :-
    A8
    rts

read_pads:
:   lda $4212               ; wait for the auto-joypad read to finish
    and #$01
    bne :-
    A16
    lda pad1
    eor #$FFFF
    and $4218
    sta pad1_new
    lda $4218
    sta pad1
    lda pad2
    eor #$FFFF
    and $421A
    sta pad2_new
    lda $421A
    sta pad2
    A8
    rts

; ---------------------------------------------------------------- video
init_ppu:
    lda #$62                ; 16x16 / 32x32 sprites, tiles at OBJ_TILES
    sta $2101
    stz $2102
    stz $2103
    stz $2105               ; mode 0: four 2-bit backgrounds
    stz $2106
    lda #(BG1_MAP >> 8) | 1 ; 64x32 tiles
    sta $2107
    lda #(BG2_MAP >> 8)
    sta $2108
    stz $2109
    stz $210A
    stz $210B               ; BG1 and BG2 tiles at VRAM 0
    stz $210C
    ldx #0
:   stz $210D, x            ; horizontal scrolls 0; vertical -1, so tile row 0 is line 0
    stz $210D, x
    lda #$FF
    sta $210E, x
    sta $210E, x
    inx
    inx
    cpx #8
    bne :-
    ldx #$2123
:   stz a:0, x              ; windows, colour maths: off
    inx
    cpx #$2134
    bne :-
    lda #$13                ; main screen: sprites, BG2, BG1
    sta $212C
    lda #$30                ; colour maths never
    sta $2130
    lda #$E0
    sta $2132
    rts

load_palettes:
    stz $2121
    ldx #0
:   lda palette_bg, x
    sta $2122
    inx
    cpx #palette_bg_end - palette_bg
    bne :-
    lda #128
    sta $2121
    ldx #0
:   lda palette_obj, x
    sta $2122
    inx
    cpx #palette_obj_end - palette_obj
    bne :-
    rts

; DMA Y bytes from X (bank 0) to VRAM at the address already set in $2116.
dma_vram:
    lda #$80
    sta $2115
    lda #$01
    sta $4300
    lda #$18
    sta $4301
    stx $4302
    stz $4304
    sty $4305
    lda #1
    sta $420B
    rts

; Zero both background maps (VRAM $1000-$1FFF) and hide every sprite.
clear_screen:
    lda #$80
    sta $2100
    sta $2115
    ldx #BG1_MAP
    stx $2116
    lda #$09
    sta $4300
    lda #$18
    sta $4301
    ldx #.loword(zero_byte)
    stx $4302
    stz $4304
    ldx #$2000
    stx $4305
    lda #1
    sta $420B
    ldx #0
    lda #$E0                ; y = 224: below the screen
:   sta oam, x
    inx
    cpx #512
    bne :-
:   stz oam, x              ; high table: small sprites, x < 256
    inx
    cpx #544
    bne :-
    rts

; Print a text record at X: the VRAM word address, then ASCII, then 0. The
; screen must be in forced blank.
print:
    A16
    lda a:0, x
    sta $2116
    A8
    lda #$80
    sta $2115
    inx
    inx
:   lda a:0, x
    beq :+
    jsr put_char
    inx
    bra :-
:   rts

put_bcd:                    ; two BCD digits of A
    pha
    lsr
    lsr
    lsr
    lsr
    jsr put_digit
    pla
    and #$0F
put_digit:
    clc
    adc #'0'
put_char:                   ; a BG2 map entry: tile A, palette 0, high priority
    sta $2118
    lda #$20
    sta $2119
    rts

; Copy the sprite table, set the scroll, draw what changed; then screen on.
vblank_work:
    stz $2102
    stz $2103
    stz $4300
    lda #$04
    sta $4301
    ldx #oam
    stx $4302
    stz $4304
    ldx #544
    stx $4305
    lda #1
    sta $420B
    lda camera_x
    sta $210D
    lda camera_x + 1
    sta $210D
    lda game_mode
    bne @playing
    ldx #BG2_MAP + 12 * 32 + 18   ; the title's level number, read from RAM every frame
    stx $2116
    lda #$80
    sta $2115
    lda level
    cmp #3
    bcc :+
    lda #0
:   inc
    jsr put_digit
    bra @on
@playing:
    A16
    lda next_column         ; stream the next column once the camera nears it
    asl
    asl
    asl
    cmp level_width
    bcs @hud
    sta temp
    lda camera_x
    clc
    adc #264
    cmp temp
    bcc @hud
    A8
    jsr draw_column
@hud:
    A8
    jsr draw_hud
@on:
    lda #$0F
    sta $2100
    rts

; Draw ground column next_column into BG1's map and advance next_column.
draw_column:
    lda #$81                ; VRAM address steps 32 words: down the column
    sta $2115
    A16
    lda next_column
    and #$0020              ; columns 32-63 are the map's second screen
    beq :+
    lda #$0400
:   clc
    adc #BG1_MAP
    sta temp
    lda next_column
    and #$001F
    clc
    adc temp
    sta $2116
    ldx next_column
    lda ground, x
    and #$00FF
    beq :+
    eor #$FFFF              ; first ground row: 28 - height
    clc
    adc #29
    bra :++
:   lda #32                 ; a pit: no ground
:   sta temp
    lda #32                 ; the goal pole's top row, or none
    ldx next_column
    cpx goal_column
    bne :+
    lda temp
    sec
    sbc #6
:   sta temp2
    ldy #0
@row:
    lda #0                  ; sky
    cpy temp
    bcc @sky
    lda #1                  ; grass, then earth
    beq @put
    cpy temp
    beq @put
    lda #2
    bra @put
@sky:
    cpy temp2
    bcc @put
    lda #3                  ; the pole, its flag on top
    cpy temp2
    bne @put
    lda #4
@put:
    sta $2118
    iny
    cpy #28
    bne @row
    inc next_column
    A8
    rts

; The HUD: each player's 8-digit score and lives on BG2's second row.
draw_hud:
    lda #$80
    sta $2115
    ldx #ADDR_P1
    ldy #BG2_MAP + 32 + 4
    jsr hud_player
    ldx #ADDR_P2
    ldy #BG2_MAP + 32 + 20
hud_player:
    sty $2116
    lda P_SCORE + 3, x
    jsr put_bcd
    lda P_SCORE + 2, x
    jsr put_bcd
    lda P_SCORE + 1, x
    jsr put_bcd
    lda P_SCORE, x
    jsr put_bcd
    lda #' '
    jsr put_char
    lda P_LIVES, x
    jmp put_digit

; Sprites 0 and 1: the players, blinking while dying, hidden when out or off screen.
build_oam:
    stz oam + 512
    ldx #ADDR_P1
    ldy #0
    jsr oam_player
    ldx #ADDR_P2
    ldy #4
oam_player:
    lda P_STATE, x
    beq @show
    cmp #1
    bne @hide
    lda P_TIMER, x
    and #4
    bne @hide
@show:
    A16
    lda P_X, x
    sec
    sbc camera_x
    sec
    sbc #8
    sta temp                ; screen x of the sprite's left edge
    clc
    adc #16
    cmp #256 + 16
    A8
    bcs @hide
    lda temp
    sta oam, y
    lda P_Y, x
    sec
    sbc #17
    sta oam + 1, y
    lda #0
    sta oam + 2, y
    tya                     ; priority 3, palette 0 (player 1) or 1 (player 2)
    lsr
    ora #$30
    sta oam + 3, y
    lda temp + 1            ; x's ninth bit, in the high table
    and #1
    beq :+
    lda x9_bit, y
    ora oam + 512
    sta oam + 512
:   rts
@hide:
    lda #$E0
    sta oam + 1, y
    rts

x9_bit:
    .byte $01, 0, 0, 0, $04

; ---------------------------------------------------------------- modes
enter_title:
    jsr clear_screen
    stz game_mode
    stz level_done
    ldx #0
    stx camera_x
    ldx #.loword(text_title)
    jsr print
    ldx #.loword(text_level)
    jsr print
    ldx #.loword(text_start)
    jsr print
    rts

do_title:
    A16
    lda pad1_new
    ora pad2_new
    and #PAD_START
    A8
    beq :+
    jsr start_game
:   rts

start_game:
    lda level
    cmp #3
    bcc :+
    stz level               ; out of range: level 1
:   ldx #ADDR_P1
    jsr new_player
    ldx #ADDR_P2
    jsr new_player
    A16
    lda pad2_new            ; START on pad 2 brings player 2 in
    and #PAD_START
    A8
    bne :+
    lda #3
    sta ADDR_P2 + P_STATE
:   jmp load_level

new_player:
    A16
    stz P_SCORE, x
    stz P_SCORE + 2, x
    A8
    stz P_STATE, x
    stz P_DEATHS, x
    stz P_TIMER, x
    lda #3
    sta P_LIVES, x
    rts

; Set up level `level`: the ground map, the first screen, the players.
load_level:
    jsr clear_screen
    A16
    lda level
    and #$00FF
    asl
    tax
    lda level_table, x
    tax                     ; X: the level's record
    lda a:0, x              ; width in columns
    asl
    asl
    asl
    sta level_width
    lda a:2, x
    sta end_x
    lsr
    lsr
    lsr
    sta goal_column
    lda a:4, x
    sta start_x
    stz camera_x
    stz next_column
    A8
    ldy #0                  ; runs of (columns, height) until a 0 count
@run:
    lda a:6, x
    beq @rest
    sta temp
    lda a:7, x
:   sta ground, y
    iny
    dec temp
    bne :-
    inx
    inx
    bra @run
@rest:
    lda #4                  ; after the runs: flat ground
:   cpy #256
    beq :+
    sta ground, y
    iny
    bra :-
:   jsr draw_column         ; the first screen and one column more
    lda next_column
    cmp #33
    bne :-
    ldx #.loword(text_p1)
    jsr print
    ldx #.loword(text_p2)
    jsr print
    stz level_done
    lda #1
    sta game_mode
    ldx #ADDR_P1
    A16
    lda start_x
    jsr place_player
    ldx #ADDR_P2
    A16
    lda start_x
    sec
    sbc #16
    ; fall through

; Put player X at x = A (16-bit A on entry) on the ground, standing.
place_player:
    .a16
    sta P_X, x
    lsr
    lsr
    lsr
    lsr
    sta P_BEST, x
    lda P_X, x
    jsr ground_top
    xba
    and #$FF00              ; y = the top, its fraction 0
    sta P_YSUB, x
    stz P_VY, x
    A8
    lda #1
    sta P_ON_GROUND, x
    lda P_STATE, x          ; a player dying when the level ended lives on, or is out
    cmp #1
    bne :++
    lda P_LIVES, x
    beq :+
    stz P_STATE, x
    rts
:   lda #2
    sta P_STATE, x
:   rts

do_play:
    ldx #ADDR_P1
    ldy #0
    jsr update_player
    ldx #ADDR_P2
    ldy #2
    jsr update_player
    lda ADDR_P2 + P_STATE   ; player 2 joins with any button on pad 2
    cmp #3
    bne :+
    A16
    lda pad2_new
    A8
    beq :+
    ldx #ADDR_P2
    jsr new_player
    jsr respawn
:   lda game_mode
    cmp #1
    bne @done
    ; The camera follows player 1 (player 2 once player 1 is out), never back.
    ldx #ADDR_P1
    lda P_STATE, x
    cmp #2
    bcc :+
    ldx #ADDR_P2
:   A16
    lda P_X, x
    sec
    sbc #112
    bmi @over
    cmp camera_x
    bcc @over
    sta temp
    lda level_width
    sec
    sbc #256
    cmp temp
    bcc :+
    lda temp
:   sta camera_x
@over:
    A8
    lda ADDR_P1 + P_STATE   ; game over when no player is left in the game
    cmp #2
    bne @done
    lda ADDR_P2 + P_STATE
    cmp #2
    bcc @done
    lda #3
    sta game_mode
    ldx #180
    stx mode_timer
    jsr clear_screen
    ldx #.loword(text_over)
    jmp print
@done:
    rts

do_clear:
    ldx mode_timer
    dex
    stx mode_timer
    bne :++
    lda level
    inc
    cmp #3
    bcs :+
    sta level
    jmp load_level
:   stz level               ; after the last level: the title, level 1
    jmp enter_title
:   rts

do_gameover:
    ldx mode_timer
    dex
    stx mode_timer
    bne :+
    stz level
    jmp enter_title
:   rts

; ---------------------------------------------------------------- players
; Player X (record), pad Y (0 or 2): one frame.
update_player:
    lda P_STATE, x
    beq @alive
    cmp #1
    bne @rts
    dec P_TIMER, x          ; dying: after the animation, back in, or out
    bne @rts
    lda P_LIVES, x
    beq :+
    jmp respawn
:   lda #2
    sta P_STATE, x
@rts:
    rts
@alive:
    A16
    lda pad1, y             ; LEFT or RIGHT (both or neither: stand)
    and #PAD_LR
    cmp #$0100
    beq @right
    cmp #$0200
    bne @vertical
    lda P_X, x
    sec
    sbc #SPEED
    sta temp
    lda camera_x            ; not off the screen's left edge
    clc
    adc #8
    cmp temp
    bcs @vertical
    bra @move
@right:
    lda P_X, x
    clc
    adc #SPEED
    sta temp
    lda camera_x            ; not off the screen's right edge
    clc
    adc #248
    cmp temp
    bcc @vertical
@move:
    lda temp                ; ground above the feet is a wall
    jsr ground_top
    sta temp2
    jsr player_y
    cmp temp2
    beq :+
    bcs @vertical           ; feet below the top: a wall
:   lda temp
    sta P_X, x
@vertical:
    A8
    lda P_ON_GROUND, x
    beq @air
    A16
    lda pad1_new, y
    and #PAD_JUMP
    beq :+
    lda #JUMP_VY
    sta P_VY, x
    A8
    stz P_ON_GROUND, x
    bra @air
:   lda P_X, x              ; walked off an edge?
    jsr ground_top
    sta temp2
    jsr player_y
    cmp temp2
    beq @progress
    A8
    stz P_ON_GROUND, x
@air:
    A16
    jsr player_y
    sta temp2               ; y before the move
    lda P_YSUB, x
    clc
    adc P_VY, x
    sta P_YSUB, x
    lda P_VY, x
    clc
    adc #GRAVITY
    bmi :+
    cmp #MAX_VY
    bcc :+
    lda #MAX_VY
:   sta P_VY, x
    jsr player_y
    cmp temp2
    beq @fell
    bcc @fell               ; going up
    sta temp3               ; y after the move
    lda P_X, x
    jsr ground_top
    cmp temp2               ; land if the top is between the old and new feet
    bcc @fell
    cmp temp3
    beq :+
    bcs @fell
:   xba
    and #$FF00
    sta P_YSUB, x
    stz P_VY, x
    A8
    lda #1
    sta P_ON_GROUND, x
    A16
@fell:
    jsr player_y
    cmp #FALL_Y
    bcc @progress
    A8
    jmp kill
@progress:
    .a16
    lda P_X, x              ; 10 points for each new 16 pixels
    lsr
    lsr
    lsr
    lsr
    cmp P_BEST, x
    beq :+
    bcc :+
    sta P_BEST, x
    lda #$0010
    jsr add_score
:   lda P_X, x
    cmp end_x
    A8
    bcc :+
    A16                     ; the goal: 1000 points, the level is done
    lda #$1000
    jsr add_score
    A8
    lda #1
    sta level_done
    lda #2
    sta game_mode
    ldx #120
    stx mode_timer
    jsr clear_screen
    ldx #.loword(text_clear)
    jmp print
:   rts

; A16 in and out: player X's feet y.
player_y:
    .a16
    lda P_YSUB, x
    xba
    and #$00FF
    rts

; A16 in and out: BCD A added to player X's score.
add_score:
    .a16
    sed
    clc
    adc P_SCORE, x
    sta P_SCORE, x
    lda P_SCORE + 2, x
    adc #0
    sta P_SCORE + 2, x
    cld
    rts

; A16 in and out: the top of the ground under level pixel x = A (PIT_TOP over a pit).
ground_top:
    .a16
    lsr
    lsr
    lsr
    cmp #256
    bcs @flat
    phx
    tax
    lda ground, x
    plx
    and #$00FF
    beq @pit
    asl
    asl
    asl
    eor #$FFFF              ; 224 - 8 * height
    sec
    adc #224
    rts
@pit:
    lda #PIT_TOP
    rts
@flat:
    lda #192
    rts

; Player X loses a life: the death animation starts.
kill:
    .a8
    lda #1
    sta P_STATE, x
    lda #60
    sta P_TIMER, x
    dec P_LIVES, x
    inc P_DEATHS, x
    A16
    stz P_VY, x
    A8
    rts

; Player X comes back on the first ground 24 pixels or more right of the screen's left edge.
respawn:
    A16
    lda camera_x
    clc
    adc #24
:   sta temp
    jsr ground_top
    cmp #PIT_TOP
    bne :+
    lda temp
    clc
    adc #8
    bra :-
:   lda temp
    and #$FFF8
    ora #4
    sta P_X, x
    lda temp
    jsr ground_top
    xba
    and #$FF00
    sta P_YSUB, x
    stz P_VY, x
    A8
    lda #1
    sta P_ON_GROUND, x
    stz P_STATE, x
    rts

; ---------------------------------------------------------------- data
.segment "RODATA"

zero_byte:
    .byte 0

; BGR555 colours. Backgrounds: BG1 palette 0 (sky, grass, earth, pole), BG2 palette 0 (text).
palette_bg:
    .word $7E8D, $1304, $1572, $7FFF
    .res 28 * 2, 0
    .word $0000, $7FFF, $0000, $03FF
palette_bg_end:
; Sprites: palette 0 (player 1, blue), palette 1 (player 2, orange).
palette_obj:
    .word $0000, $7D08, $7FFF, $0000
    .res 12 * 2, 0
    .word $0000, $021F, $7FFF, $0000
palette_obj_end:

text_title: .word BG2_MAP + 8 * 32 + 12
    .byte "SKIPPER", 0
text_level: .word BG2_MAP + 12 * 32 + 12
    .byte "LEVEL", 0
text_start: .word BG2_MAP + 16 * 32 + 10
    .byte "PRESS START", 0
text_p1: .word BG2_MAP + 32 + 1
    .byte "1P", 0
text_p2: .word BG2_MAP + 32 + 17
    .byte "2P", 0
text_clear: .word BG2_MAP + 10 * 32 + 13
    .byte "CLEAR", 0
text_over: .word BG2_MAP + 10 * 32 + 11
    .byte "GAME OVER", 0

; Levels: width in columns, goal x, start x, then runs of (columns, height in
; tiles; 0 = a pit), ended by 0; flat ground of height 4 after the runs.
level_table:
    .word level1, level2, level3
level1:
    .word 160, 1200, 40
    .byte 44,4, 3,0, 16,4, 3,0, 14,4, 4,0, 18,4, 3,0, 12,4, 4,0, 0
level2:
    .word 192, 1440, 40
    .byte 20,4, 4,0, 10,4, 8,5, 4,0, 10,5, 6,4, 4,0, 12,4, 3,0, 6,4, 3,0
    .byte 14,4, 4,0, 10,4, 12,6, 4,0, 0
level3:
    .word 224, 1700, 40
    .byte 16,4, 4,0, 8,5, 12,6, 4,0, 8,6, 4,5, 3,0, 10,4, 4,0, 6,4, 4,0
    .byte 8,5, 3,0, 8,6, 4,0, 12,4, 4,0, 6,5, 12,6, 4,0, 10,4, 4,0, 0

.include "art.inc"

; ---------------------------------------------------------------- header
.segment "HEADER"
    .byte "SKIPPER              "   ; title, 21 bytes
    .byte $20                       ; LoROM, 2.68 MHz ROM
    .byte $00                       ; ROM only
    .byte $05                       ; ROM size: 2^5 KiB
    .byte $00                       ; no cartridge RAM
    .byte $01                       ; North America (NTSC)
    .byte $00                       ; developer
    .byte $00                       ; version 1.0
    .word $FFFF                     ; checksum complement (fixheader.py)
    .word $0000                     ; checksum (fixheader.py)

.segment "VECTORS"
    ; native mode: -, -, COP, BRK, ABORT, NMI, -, IRQ
    .word 0, 0, ignore, ignore, ignore, nmi, 0, ignore
    ; emulation mode: -, -, COP, -, ABORT, NMI, RESET, IRQ/BRK
    .word 0, 0, ignore, 0, ignore, ignore, reset, ignore
