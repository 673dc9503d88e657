/*
 * Dasher: hardware set-up, the game modes and the main loop.
 *
 * The loop runs once per frame, in step with the VBlank interrupt:
 *   wait for VBlank -> update the screen from the last frame's state ->
 *   read both pads -> run one frame of game logic.
 */
#include "art.h"
#include "levels.h"
#include "objects.h"
#include "pad.h"
#include "player.h"
#include "ram.h"
#include "screen.h"
#include "util.h"
#include "vdp.h"
#include "world.h"

#define CLEAR_FRAMES 120
#define GAMEOVER_FRAMES 180

/* Park the Z80 on "di; halt" and silence the PSG: the game has no sound. */
static void sound_off(void)
{
    Z80_BUSREQ = 0x100;
    Z80_RESET = 0x100;
    while (Z80_BUSREQ & 0x100) /* bit 8 reads 0 once the bus is ours */
        ;
    Z80_RAM[0] = 0xF3; /* di */
    Z80_RAM[1] = 0x76; /* halt */
    Z80_RESET = 0;
    Z80_BUSREQ = 0;
    Z80_RESET = 0x100;
    PSG_PORT = 0x9F; /* four channels to volume off */
    PSG_PORT = 0xBF;
    PSG_PORT = 0xDF;
    PSG_PORT = 0xFF;
}

/* ---- modes --------------------------------------------------------------- */

static void title_enter(void)
{
    vdp_display(0);
    RAM.game_mode = MODE_TITLE;
    RAM.level_done = 0;
    screen_title_draw();
    vdp_display(1);
}

static struct player *focus(void)
{
    if (RAM.p[0].state == PS_ALIVE || RAM.p[0].state == PS_DYING)
        return &RAM.p[0];
    return &RAM.p[1];
}

/* Load the act RAM.zone / RAM.act; every player still in the game starts
 * it at the act's start. */
static void act_enter(void)
{
    u16 i;
    vdp_display(0);
    world_load(RAM.zone, RAM.act);
    for (i = 0; i < 2; i++) {
        struct player *p = &RAM.p[i];
        if (p->state == PS_DYING && p->lives == 0)
            p->state = PS_OUT;
        if (p->state == PS_ALIVE || p->state == PS_DYING)
            player_spawn(p, i);
    }
    RAM.level_done = 0;
    RAM.game_mode = MODE_PLAY;
    world_follow(focus()->x);
    vdp_set_reg(18, 2); /* window plane (HUD) over the top 16 lines */
    screen_play_update();
    vdp_display(1);
}

/* START on either pad.  The zone and act are read from RAM here, after all
 * set-up, so a level select written by a tool at any time before is used. */
static void game_start(u8 with_p2)
{
    u16 i;
    if (RAM.zone >= ZONES)
        RAM.zone = 0;
    if (RAM.act >= ACTS)
        RAM.act = 0;
    for (i = 0; i < 2; i++) {
        struct player *p = &RAM.p[i];
        u16 j;
        p->lives = START_LIVES;
        for (j = 0; j < 4; j++)
            p->score[j] = 0;
        p->rings = 0;
        p->deaths = 0;
        p->state = (i == 0 || with_p2) ? PS_ALIVE : PS_ABSENT;
    }
    act_enter();
}

static void title_frame(void)
{
    if ((RAM.pad_new[0] | RAM.pad_new[1]) & PAD_START)
        game_start(RAM.pad_new[1] & PAD_START);
}

static void play_frame(void)
{
    u16 i;
    struct player *p2 = &RAM.p[1];
    if (p2->state == PS_ABSENT && RAM.pad_new[1]) { /* player 2 joins */
        p2->lives = START_LIVES;
        player_spawn(p2, 1);
    }
    enemies_update();
    for (i = 0; i < 2; i++) {
        player_update(&RAM.p[i], i, RAM.pad[i], RAM.pad_new[i]);
        objects_touch(&RAM.p[i]);
    }
    world_follow(focus()->x);
    for (i = 0; i < 2; i++) {
        struct player *p = &RAM.p[i];
        if (p->state == PS_ALIVE && p->x >= (s16)RAM.end_x) { /* goal! */
            u16 j;
            RAM.level_done = 1;
            RAM.game_mode = MODE_CLEAR;
            RAM.mode_timer = CLEAR_FRAMES;
            for (j = 0; j < 2; j++)
                if (RAM.p[j].state == PS_ALIVE)
                    score_add(RAM.p[j].score, 0x1000);
            screen_banner("ACT CLEAR!");
            return;
        }
    }
    if (RAM.p[0].state == PS_OUT && (p2->state == PS_OUT || p2->state == PS_ABSENT)) {
        RAM.game_mode = MODE_GAMEOVER;
        RAM.mode_timer = GAMEOVER_FRAMES;
        screen_banner("GAME OVER");
    }
}

static void clear_frame(void)
{
    if (--RAM.mode_timer)
        return;
    if (++RAM.act >= ACTS) {
        RAM.act = 0;
        if (++RAM.zone >= ZONES) { /* all six acts done: back to the title */
            RAM.zone = 0;
            title_enter();
            return;
        }
    }
    act_enter();
}

static void gameover_frame(void)
{
    if (--RAM.mode_timer)
        return;
    RAM.zone = 0;
    RAM.act = 0;
    title_enter();
}

/* ---- main ------------------------------------------------------------------ */

void game_main(void)
{
    sound_off();
    vdp_init();
    pad_init();
    art_load();
    RAM.selftest = math_selftest() ? 1 : 0xEE;
    title_enter();
    __asm__ volatile("move.w #0x2000, %sr"); /* let the VBlank interrupt in */
    for (;;) {
        vdp_wait_vblank();
        if (RAM.game_mode == MODE_TITLE)
            screen_title_update();
        else
            screen_play_update();
        pad_read_all();
        RAM.frame++;
        rng_stir();
        switch (RAM.game_mode) {
        case MODE_TITLE:
            title_frame();
            break;
        case MODE_PLAY:
            play_frame();
            break;
        case MODE_CLEAR:
            clear_frame();
            break;
        default:
            gameover_frame();
            break;
        }
    }
}
