/*
 * Screen output.  The HUD lives in the window plane (top two cell rows,
 * not scrolled), terrain in plane A, the background in plane B, and players
 * and crawlers are 16x16 sprites.
 */
#include "screen.h"
#include "art.h"
#include "levels.h"
#include "ram.h"
#include "util.h"
#include "vdp.h"
#include "world.h"

#define MAX_SPRITES 16
#define SPRITE_2X2 0x0500 /* size bits: 2 cells wide, 2 high */

static u16 sprites[MAX_SPRITES][4];
static u16 sprite_count;

static void sprite_add(s16 x, s16 y, u16 attr)
{
    if (sprite_count >= MAX_SPRITES || x <= -16 || x >= SCREEN_W || y <= -16 || y >= SCREEN_H)
        return;
    sprites[sprite_count][0] = y + 128; /* the VDP's sprite origin is (-128, -128) */
    sprites[sprite_count][1] = SPRITE_2X2;
    sprites[sprite_count][2] = attr;
    sprites[sprite_count][3] = x + 128;
    sprite_count++;
}

/* Upload the sprite list; each entry links to the next, the last to 0. */
static void sprites_flush(void)
{
    u16 i;
    if (sprite_count == 0) {
        sprites[0][0] = 0; /* one sprite far above the screen */
        sprites[0][2] = 0;
        sprites[0][3] = 0;
        sprite_count = 1;
    }
    vdp_vram_write_addr(VRAM_SPRITES);
    for (i = 0; i < sprite_count; i++) {
        u16 link = i + 1 < sprite_count ? i + 1 : 0;
        VDP_DATA = sprites[i][0];
        VDP_DATA = (sprites[i][1] & 0x0F00) | link;
        VDP_DATA = sprites[i][2];
        VDP_DATA = sprites[i][3];
    }
    sprite_count = 0;
}

static void draw_player(const struct player *p, u16 index, s16 cam)
{
    u16 frame;
    if (p->state != PS_ALIVE && p->state != PS_DYING)
        return;
    if (p->invuln && (RAM.frame & 4)) /* blink while invulnerable */
        return;
    if (p->state == PS_DYING || !p->on_ground)
        frame = PLAYER_BALL;
    else if (p->vx == 0)
        frame = PLAYER_STAND;
    else
        frame = (p->anim & 0x80) ? PLAYER_RUN2 : PLAYER_RUN1;
    sprite_add(p->x - cam - 8, p->y - 16,
               TILE_ATTR(index ? PAL_P2 : PAL_P1, 1, p->facing, T_PLAYER + 4 * frame));
}

static void draw_enemies(s16 cam)
{
    u16 i;
    for (i = 0; i < RAM.enemy_count; i++) {
        const struct enemy *e = &RAM.enemies[i];
        u16 frame = (e->state == 1 && (e->x & 8)) ? 4 : 0;
        if (e->state)
            sprite_add(e->x - cam - 8, e->y - 16,
                       TILE_ATTR(PAL_ENEMY, 1, e->dir > 0, T_ENEMY + frame));
    }
}

/* "1P 00001230 RINGS 012 LIVES 3" */
static void hud_player(char *line, const struct player *p, u16 index)
{
    static const char absent[] = "PUSH ANY BUTTON ON PAD 2";
    static const char out[] = "GAME OVER";
    u16 i;
    line[0] = '1' + index;
    line[1] = 'P';
    if (p->state == PS_ABSENT || p->state == PS_OUT) {
        const char *s = p->state == PS_ABSENT ? absent : out;
        for (i = 0; s[i]; i++)
            line[3 + i] = s[i];
        return;
    }
    for (i = 0; i < 8; i++) {
        u8 b = p->score[i >> 1];
        line[3 + i] = '0' + ((i & 1) ? (b & 0x0F) : (b >> 4));
    }
    for (i = 0; i < 5; i++)
        line[12 + i] = "RINGS"[i];
    put_decimal(line + 18, p->rings, 3);
    for (i = 0; i < 5; i++)
        line[22 + i] = "LIVES"[i];
    line[28] = '0' + (p->lives > 9 ? 9 : p->lives);
}

static void hud_draw(void)
{
    char line[41];
    u16 row, i;
    for (row = 0; row < 2; row++) {
        for (i = 0; i < 40; i++)
            line[i] = ' ';
        line[40] = 0;
        hud_player(line, &RAM.p[row], row);
        if (row == 0) {
            for (i = 0; i < 4; i++)
                line[32 + i] = "ZONE"[i];
            line[37] = '1' + RAM.zone;
            line[38] = '-';
            line[39] = '1' + RAM.act;
        }
        vdp_text(VRAM_WINDOW, 0, row, line, TILE_ATTR(PAL_TERRAIN, 1, 0, T_FONT));
    }
}

void screen_play_update(void)
{
    s16 cam = RAM.camera_x;
    world_scroll();
    draw_player(&RAM.p[0], 0, cam);
    draw_player(&RAM.p[1], 1, cam);
    draw_enemies(cam);
    sprites_flush();
    hud_draw();
}

void screen_banner(const char *text)
{
    u16 len = 0, col;
    while (text[len])
        len++;
    col = ((RAM.camera_x >> 3) + 20 - len / 2) & (PLANE_W - 1);
    while (*text) {
        vdp_put(VRAM_PLANE_A, col, 10, TILE_ATTR(PAL_TERRAIN, 1, 0, T_FONT + (u8)*text++));
        col = (col + 1) & (PLANE_W - 1);
    }
}

/* ---- title --------------------------------------------------------------- */

static u16 selected_zone(void)
{
    return RAM.zone < ZONES ? RAM.zone : 0;
}

/* The title has no HUD, so no dark bar behind it either. */
static void clear_hud_bar(void)
{
    u16 i;
    vdp_vram_write_addr(VRAM_PLANE_B);
    for (i = 0; i < 2 * PLANE_W; i++)
        VDP_DATA = 0;
}

static void text_centre(u16 row, const char *s)
{
    u16 len = 0;
    while (s[len])
        len++;
    vdp_text(VRAM_PLANE_A, 20 - len / 2, row, s, TILE_ATTR(PAL_TERRAIN, 1, 0, T_FONT));
}

void screen_title_draw(void)
{
    u16 col, row;
    vdp_set_reg(18, 0); /* no HUD window */
    vdp_fill_plane(VRAM_PLANE_A, 0);
    world_draw_background(selected_zone());
    clear_hud_bar();
    for (col = 0; col < 40; col++) {
        vdp_put(VRAM_PLANE_A, col, 24, TILE_ATTR(PAL_TERRAIN, 0, 0, T_GRASS));
        for (row = 25; row < 28; row++)
            vdp_put(VRAM_PLANE_A, col, row, TILE_ATTR(PAL_TERRAIN, 0, 0, row < 27 ? T_DIRT : T_DIRT_DEEP));
    }
    text_centre(5, "D A S H E R");
    text_centre(7, "A TINY PLATFORMER");
    text_centre(19, "RETROKIT TEST CARTRIDGE");
    vdp_hscroll(0, 0);
}

/* Every frame: the level select is shown from RAM, so a zone or act written
 * by a tool appears at once (the palette follows the zone too).  Kept short
 * so the loop never misses a frame, and with it a START press. */
void screen_title_update(void)
{
    u16 zone = selected_zone();
    char line[] = "ZONE 1  ACT 1";
    u16 act = RAM.act < 2 ? RAM.act : 0;
    art_zone_palette(zone);
    line[5] = '1' + zone;
    line[12] = '1' + act;
    text_centre(11, line);
    text_centre(13, "                ");
    text_centre(13, zone_names[zone]);
    text_centre(17, (RAM.frame & 32) ? "           " : "PRESS START");
    vdp_hscroll(0, -(s16)(RAM.frame >> 2));
    sprite_add(144, 176, TILE_ATTR(PAL_P1, 1, 0, T_PLAYER + 4 * PLAYER_STAND));
    sprite_add(162, 176, TILE_ATTR(PAL_P2, 1, 1, T_PLAYER + 4 * PLAYER_STAND));
    sprites_flush();
}
