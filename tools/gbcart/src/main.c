/*
 * Trekker: the game modes and the main loop.
 *
 * One pass of the loop per frame: wait for VBlank, update VRAM and OAM, read
 * the pad, stir the random state, then run the current mode.
 */
#include "hw.h"
#include "ram.h"
#include "game.h"

#ifdef COLOR
#define BUILD 1
#else
#define BUILD 0
#endif

static void read_pad(void) {
    uint8_t dpad, buttons, now;
    rP1 = 0x20; /* select the d-pad; reading twice lets the lines settle */
    dpad = rP1;
    dpad = rP1;
    rP1 = 0x10; /* select the buttons */
    buttons = rP1;
    buttons = rP1;
    buttons = rP1;
    rP1 = 0x30;
    now = (uint8_t)(~dpad & 0x0F) | (uint8_t)((~buttons & 0x0F) << 4);
    pad_new = now & (uint8_t)~pad;
    pad = now;
}

/* xorshift, then the frame counter and the pad stirred in: the same inputs
 * replay the same game, while a press a frame later changes it. */
static void stir_rng(void) {
    uint16_t r = rng;
    r ^= r << 7;
    r ^= r >> 9;
    r ^= r << 8;
    rng = r + (uint8_t)frame_lo + pad;
    if (!++frame_lo)
        ++frame_hi;
}

static void show_title(void) {
    lcd_off();
    game_mode = MODE_TITLE;
    level_done = 0;
    camera_x = 0;
    clear_bg();
    draw_text(4, 6, "TREKKER");
    draw_text(8, 6, "WORLD 1");
    draw_text(12, 4, "PRESS START");
    hud_show_score();
    build_sprites();
    set_palettes();
    lcd_on();
}

/* Start (or restart, after a lost life) the current level. */
void start_level(void) {
    lcd_off();
    load_level_map();
    camera_x = 0;
    player_spawn();
    set_palettes();
    clear_bg();
    draw_level_screen();
    level_done = 0;
    game_mode = MODE_PLAY;
    hud_show_score();
    build_sprites();
    lcd_on();
}

static void title_step(void) {
    if (pad_new & PAD_START) {
        uint8_t i;
        if (level >= LEVELS)
            level = 0;
        player.lives = 3;
        player.deaths = 0;
        player.coins = 0;
        for (i = 0; i < 4; ++i)
            player.score[i] = 0;
        start_level();
    }
}

void main(void) {
    color_build = BUILD;
    if (level >= LEVELS)
        level = 0; /* power-on RAM: anything */
    rNR52 = 0;     /* no sound */
    video_init();
    show_title();
    rIF = 0;
    rIE = 0x01; /* VBlank only */
    __asm__("ei");
    for (;;) {
        wait_vblank();
        vblank_work();
        read_pad();
        stir_rng();
        switch (game_mode) {
        case MODE_TITLE:
            title_step();
            break;
        case MODE_PLAY:
            play_step();
            break;
        case MODE_CLEAR:
            if (!--mode_timer) {
                if (++level >= LEVELS) {
                    level = 0;
                    show_title();
                } else {
                    start_level();
                }
            }
            break;
        default: /* game over */
            if (!--mode_timer) {
                level = 0;
                show_title();
            }
            break;
        }
        build_sprites();
    }
}
