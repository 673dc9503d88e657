/* Skipper: a small PC Engine platformer for retrokit's tests. The title, the
 * game's modes, the pad, the random state, the score and the HUD. */
#include "art.h"
#include "hw.h"
#include "levels.h"
#include "player.h"
#include "ram.h"
#include "score.h"
#include "video.h"
#include "world.h"

#define CLEAR_FRAMES 120
#define GAMEOVER_FRAMES 180
#define DEATH_FRAMES 90
#define SPR_HUD 7  /* sprites 7-14: heart, lives, six score digits */

unsigned char joypad_read(void);

static void read_pad(void) {
    unsigned char held = joypad_read(), old = PAD;
    PAD = held;
    PAD_NEW = held & ~old;
}

/* xorshift, stirred every frame by the frame counter and the pad. */
static void stir_random(void) {
    unsigned r = RNG;
    r ^= r << 7;
    r ^= r >> 9;
    r ^= r << 8;
    RNG = r + (FRAME ^ PAD);
}

/* Adds a BCD byte to the score's byte n (0 most significant), carrying up. */
void add_score(unsigned char n, unsigned char bcd) {
    unsigned char lo, hi, carry;
    for (;;) {
        lo = (SCORE[n] & 15) + (bcd & 15);
        hi = (SCORE[n] >> 4) + (bcd >> 4);
        if (lo > 9) {
            lo -= 10;
            ++hi;
        }
        carry = hi > 9;
        if (carry) hi -= 10;
        SCORE[n] = (hi << 4) | lo;
        if (!carry || n == 0) return;
        --n;
        bcd = 1;
    }
}

static void show_title_level(void) {
    static char line[] = "LEVEL 1";
    line[6] = '1' + (LEVEL < LEVELS ? LEVEL : 0);
    text(12, 14, line);
}

/* The title: mode 0 only once drawn, so a RUN pressed from then on is seen. */
static void enter_title(void) {
    CAMERA_X = 0;
    bat_clear();
    sprites_hide_from(0);
    text(12, 8, "SKIPPER");
    show_title_level();
    text(12, 18, "PUSH RUN");
    text(7, 26, "RETROKIT TEST CARTRIDGE");
    GAME_MODE = MODE_TITLE;
}

static void start_level(void) {
    if (LEVEL >= LEVELS) LEVEL = 0;
    LEVEL_DONE = 0;
    CAMERA_X = 0;
    world_load();
    player_spawn();
    bat_clear();
    world_draw();
    GAME_MODE = MODE_PLAY;
}

static void start_game(void) {
    LIVES = 3;
    DEATHS = 0;
    COINS = 0;
    SCORE[0] = SCORE[1] = SCORE[2] = SCORE[3] = 0;
    start_level();
}

static void message(const char *s) {
    text((unsigned char)((CAMERA_X >> 3) + 12), 11, s);
}

static void play(void) {
    crawlers_move();
    player_update();
    if (PSTATE == DYING) {
        if (TIMER >= DEATH_FRAMES) {
            if (LIVES == 0) {
                GAME_MODE = MODE_GAMEOVER;
                MODE_TIMER = GAMEOVER_FRAMES;
                message("GAME OVER");
            } else {
                start_level();
            }
        }
        return;
    }
    camera_follow();
    if (PX >= END_X) {
        LEVEL_DONE = 1;
        add_score(2, 0x10);  /* 1000 points */
        GAME_MODE = MODE_CLEAR;
        MODE_TIMER = CLEAR_FRAMES;
        message(" CLEAR! ");
    }
}

static void draw_sprites(void) {
    struct enemy *e = ENEMY;
    unsigned char i, n = 1, d;
    int sx;
    unsigned cam = CAMERA_X;
    if (GAME_MODE == MODE_TITLE) {
        sprites_hide_from(0);
        return;
    }
    sprite(0, (int)(PX - cam) - 8, PY - 16, S_PLAYER, SPR_FRONT | SPR_PAL_PLAYER | (FACING ? SPR_FLIP_X : 0));
    for (i = 0; i < ENEMY_COUNT; ++i, ++e) {
        sx = (int)(e->x - cam) - 8;
        if (e->state && sx > -16 && sx < 256) {
            sprite(n++, sx, (int)e->y - 15, S_CRAWLER, SPR_FRONT | SPR_PAL_CRAWLER | (e->dir < 0 ? SPR_FLIP_X : 0));
        }
    }
    sprites_hide_from(n);
    sprite(SPR_HUD, 200, 10, S_HEART, SPR_FRONT | SPR_PAL_HUD);
    sprite(SPR_HUD + 1, 212, 10, S_DIGITS + ((LIVES > 9 ? 9 : LIVES) << 6), SPR_FRONT | SPR_PAL_HUD);
    for (i = 0; i < 6; ++i) {
        d = SCORE[1 + (i >> 1)];
        d = (i & 1) ? d & 15 : d >> 4;
        sprite(SPR_HUD + 2 + i, 16 + 8 * i, 10, S_DIGITS + ((unsigned)d << 6), SPR_FRONT | SPR_PAL_HUD);
    }
}

void main(void) {
    video_init();
    art_init();
    enter_title();
    for (;;) {
        wait_frame();
        vdc_reg(VDC_BXR, CAMERA_X & 511);  /* the scroll of the frame the sprites below show in */
        VDC_SELECT = VDC_VWR;
        read_pad();
        ++FRAME;
        stir_random();
        switch (GAME_MODE) {
        case MODE_TITLE:
            show_title_level();
            if (PAD_NEW & PAD_RUN) start_game();
            break;
        case MODE_PLAY:
            play();
            break;
        case MODE_CLEAR:
            if (--MODE_TIMER == 0) {
                ++LEVEL;
                if (LEVEL >= LEVELS) {
                    LEVEL = 0;
                    enter_title();
                } else {
                    start_level();
                }
            }
            break;
        default:
            if (--MODE_TIMER == 0) enter_title();
            break;
        }
        draw_sprites();
        sprites_flush();  /* the VDC copies the table at the next vertical blank: shown next frame */
    }
}
