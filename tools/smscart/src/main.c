/* Hopper: a small run-and-jump game for the Master System and Game Gear.
 * Game modes and the main loop; see README.md for the game and its RAM map. */
#include "hopper.h"

volatile Game __at(ADDR_LEVEL) G;

#define CLEAR_FRAMES 120
#define GAMEOVER_FRAMES 180

/* Text at a window row, centred in the visible window at the camera. */
static void text_centred(uint8_t row, const char *text, uint8_t len)
{
    vdp_text((G.camera_x + SCREEN_W / 2) / 8 - len / 2, row, text);
}

static void title_show_level(void)
{
    uint8_t level = G.level < level_count() ? G.level : 0;
    vdp_put_tile(SCREEN_W / 16 + 3, SCREEN_TOP / 8 + 9, '1' + level);
}

static void title_enter(void)
{
    vdp_display(0);
    G.game_mode = MODE_TITLE;
    G.camera_x = 0;
    G.level_done = 0;
    vdp_set_reg(8, SCREEN_LEFT);
    vdp_set_sky(0);
    vdp_clear_map();
    G.sat[0] = 0xD0;
    vdp_upload_sat();
    text_centred(SCREEN_TOP / 8 + 5, "HOPPER", 6);
    text_centred(SCREEN_TOP / 8 + 9, "LEVEL  ", 7);
    text_centred(SCREEN_TOP / 8 + 13, "PRESS START", 11);
#if PLAYERS == 2
    text_centred(SCREEN_TOP / 8 + 15, "2P PRESS 1 ON PAD 2", 19);
#endif
    title_show_level();
    vdp_display(1);
}

static void level_begin(void)
{
    vdp_display(0);
    if (G.level >= level_count())
        G.level = 0;
    world_load(G.level);
    G.camera_x = 0;
    G.level_done = 0;
    vdp_clear_map();
    players_spawn();
    world_redraw();
    vdp_set_sky(G.level);
    vdp_set_reg(8, SCREEN_LEFT);
    sprites_build();
    vdp_upload_sat();
    G.game_mode = MODE_PLAY;
    vdp_display(1);
}

static void game_start(uint8_t players)
{
    uint8_t i, k;
    for (i = 0; i < 2; i++) {
        volatile Player *p = &G.p[i];
        for (k = 0; k < PLAYER_SIZE; k++)
            ((volatile uint8_t *)p)[k] = 0;
        p->lives = 3;
        p->state = i < players ? PS_ALIVE : PS_ABSENT;
    }
    level_begin();
}

static void title_update(void)
{
    title_show_level();
#if PLAYERS == 2
    if (G.pad2_new & (PAD_B1 | PAD_B2)) {
        game_start(2);
        return;
    }
#endif
    if (G.pad1_new & (PAD_START | PAD_B1 | PAD_B2))
        game_start(1);
}

/* The camera follows the player furthest right, a third of the window in;
 * it never scrolls back. */
static void camera_update(void)
{
    uint16_t lead = 0, limit = G.level_width - SCREEN_W;
    uint8_t i;
    for (i = 0; i < PLAYERS; i++)
        if (G.p[i].state == PS_ALIVE && G.p[i].x > lead)
            lead = G.p[i].x;
    if (lead > G.camera_x + SCREEN_W / 3) {
        G.camera_x = lead - SCREEN_W / 3;
        if (G.camera_x > limit)
            G.camera_x = limit;
    }
}

static void play_update(void)
{
    uint8_t i, out = 0;
#if PLAYERS == 2
    if (G.p[1].state == PS_ABSENT && (G.pad2_new & (PAD_B1 | PAD_B2))) {
        G.p[1].lives = 3;
        player_spawn(1);  /* player 2 joins */
    }
#endif
    players_update();
    crawlers_update();
    camera_update();
    for (i = 0; i < PLAYERS; i++)
        out += G.p[i].state == PS_OUT || G.p[i].state == PS_ABSENT;
    if (G.level_done) {
        G.game_mode = MODE_CLEAR;
        G.mode_timer = CLEAR_FRAMES;
        text_centred(SCREEN_TOP / 8 + 6, "CLEAR", 5);
    } else if (out == PLAYERS) {
        G.game_mode = MODE_GAMEOVER;
        G.mode_timer = GAMEOVER_FRAMES;
        text_centred(SCREEN_TOP / 8 + 6, "GAME OVER", 9);
    }
}

void main(void)
{
    G.console = CONSOLE_GG;
    G.rng = 0x2A55;
    vdp_init();
    title_enter();
    __asm__("ei");
    for (;;) {
        wait_vblank();
        /* In the blanking: scroll, sprites and the next column. */
        vdp_set_reg(8, (uint8_t)(SCREEN_LEFT - G.camera_x));
        vdp_upload_sat();
        if (G.game_mode != MODE_TITLE)
            world_draw_ahead();

        read_pads();
        G.frame++;
        G.rng ^= G.frame ^ ((uint16_t)G.pad1 << 8) ^ G.pad2;
        rand8();
        switch (G.game_mode) {
        case MODE_TITLE:
            title_update();
            break;
        case MODE_PLAY:
            play_update();
            break;
        case MODE_CLEAR:
            if (!--G.mode_timer) {
                if (++G.level < level_count())
                    level_begin();
                else {
                    G.level = 0;
                    title_enter();
                }
            }
            break;
        default:
            if (!--G.mode_timer) {
                G.level = 0;
                title_enter();
            }
            break;
        }
        if (G.game_mode != MODE_TITLE)
            sprites_build();
    }
}
