/* Hopper: the title, the stages and the main loop. */
#include "game.h"

#define CLEAR_FRAMES 120
#define GAMEOVER_FRAMES 180

static char level_text[] = "1-1";

static void title(void)
{
    ppu_off();
    camera_x = 0;
    clear_nametables();
    text(0x2000 + 8 * 32 + 13, "HOPPER");
    text(0x2000 + 13 * 32 + 10, "LEVEL");
    text(0x2000 + 18 * 32 + 11, "PUSH START");
    queue_flush();
    game_mode = MODE_TITLE;
    draw_sprites();
    ppu_on();
    for (;;) {
        read_pads();
        /* The level select is read from RAM every frame, so a tool may set it. */
        level_text[0] = '1' + (world < 3 ? world : 0);
        level_text[2] = '1' + (stage < 2 ? stage : 0);
        text(0x2000 + 13 * 32 + 16, level_text);
        wait_frame();
        if ((pad1_new | pad2_new) & PAD_START)
            break;
    }
    players = (pad2_new & PAD_START) ? 2 : 1;
    if (world > 2 || stage > 1)
        world = stage = 0;
}

static void new_game(void)
{
    unsigned char n, i;
    struct player *p;
    for (n = 0; n < 2; ++n) {
        p = PLAYER(n);
        p->lives = 3;
        p->coins = 0;
        p->deaths = 0;
        for (i = 0; i < 6; ++i)
            p->score[i] = 0;
        p->state = n < players ? PS_ALIVE : PS_ABSENT;
    }
}

static void start_stage(void)
{
    unsigned char n;
    struct player *p;
    level_done = 0;
    load_stage();
    camera_x = 0;
    for (n = 0; n < 2; ++n) {
        p = PLAYER(n);
        if (p->state == PS_DYING)
            p->state = p->lives ? PS_ALIVE : PS_OUT;
        if (p->state == PS_ALIVE)
            player_spawn(n, start_x - 16 * n, 0);
    }
    redraw();
    game_mode = MODE_PLAY;
}

static void follow_leader(void)
{
    struct player *p = PLAYER(leader());
    unsigned target;
    if (p->state != PS_ALIVE || p->x < 120)
        return;
    target = p->x - 120;
    if (target > level_width - 256)
        target = level_width - 256;
    if (target > camera_x)
        camera_x = target;
}

static void play_frame(void)
{
    unsigned char n;
    struct player *p;
    player_update(0, pad1, pad1_new);
    player_update(1, pad2, pad2_new);
    enemies_update();
    follow_leader();
    for (n = 0; n < 2; ++n) {
        p = PLAYER(n);
        if (p->state == PS_ALIVE && p->x >= end_x) {
            level_done = 1;
            add_score(n, 2, 1);
            game_mode = MODE_CLEAR;
            mode_timer = CLEAR_FRAMES;
            screen_text(13, 12, "CLEAR!");
            return;
        }
    }
    if (PLAYER(0)->state >= PS_OUT && PLAYER(1)->state >= PS_OUT) {
        game_mode = MODE_GAMEOVER;
        mode_timer = GAMEOVER_FRAMES;
        screen_text(11, 12, "GAME OVER");
    }
}

/* Play stages from (world, stage) until game over or the last is cleared. */
static void play(void)
{
    new_game();
    for (;;) {
        start_stage();
        while (game_mode == MODE_PLAY || --mode_timer) {
            read_pads();
            if (game_mode == MODE_PLAY)
                play_frame();
            draw_sprites();
            draw_ahead();
            scroll_x = (unsigned char)camera_x;
            ppu_ctrl = 0x80 | ((camera_x >> 8) & 1);
            wait_frame();
        }
        if (game_mode == MODE_GAMEOVER || (world == 2 && stage == 1))
            break;
        if (++stage == 2) {
            stage = 0;
            ++world;
        }
    }
    world = stage = 0;
}

void main(void)
{
    ppu_init();
    for (;;) {
        title();
        play();
    }
}
