/*
 * The world: an act's terrain lives in RAM as one GROUND_* byte per 8-pixel
 * column (ADDR_GROUND), so collision is a table look-up and tools can read
 * the level.  Plane A (64 cells wide, 512 pixels) holds the terrain around
 * the camera: as the camera scrolls, columns entering the screen are drawn
 * into the plane column they wrap to.  Plane B holds a background that
 * scrolls at half speed.
 */
#include "world.h"
#include "art.h"
#include "levels.h"
#include "ram.h"
#include "vdp.h"

#define ROWS 28

static u16 level_cols(void)
{
    return RAM.level_width >> 3;
}

u8 world_ground(s16 x)
{
    u16 col;
    if (x < 0)
        return GROUND_HEIGHT; /* a wall left of the level */
    col = (u16)x >> 3;
    if (col >= level_cols())
        return 4; /* floor right of the level */
    return RAM.ground[col];
}

s16 world_ground_y(s16 x)
{
    u8 h = world_ground(x) & GROUND_HEIGHT;
    return h ? SCREEN_H - 8 * h : NO_GROUND;
}

/* ---- loading ----------------------------------------------------------- */

static void expand_terrain(const struct level *lv)
{
    const struct segment *s;
    u16 col = 0, i;
    for (s = lv->terrain; s->cols && col < MAX_COLUMNS; s++)
        for (i = 0; i < s->cols && col < MAX_COLUMNS; i++)
            RAM.ground[col++] = s->ground;
    RAM.level_width = col * 8;
    for (; col < MAX_COLUMNS; col++)
        RAM.ground[col] = 0;
}

static void expand_rings(const struct level *lv)
{
    const struct ring_line *r;
    u16 n = 0, i;
    for (r = lv->rings; r->count; r++)
        for (i = 0; i < r->count && n < MAX_RINGS; i++, n++) {
            RAM.rings[n].col = r->col + i;
            RAM.rings[n].row = r->row;
            RAM.rings[n].taken = 0;
        }
    RAM.ring_count = n;
}

/* Crawlers patrol the flat run of ground they stand on, up to 64 pixels
 * either side of their start, a tile clear of its ends. */
static void place_enemies(const struct level *lv)
{
    const u16 *x;
    u16 n = 0;
    for (x = lv->enemies; *x && n < MAX_ENEMIES; x++, n++) {
        struct enemy *e = &RAM.enemies[n];
        u8 under = world_ground(*x);
        s16 left = *x, right = *x;
        while (left > *x - 64 && world_ground(left - 8) == under)
            left -= 8;
        while (right < *x + 64 && world_ground(right + 8) == under)
            right += 8;
        e->x = *x;
        e->y = world_ground_y(*x);
        e->x0 = left;
        e->x1 = right;
        e->state = 1;
        e->dir = (n & 1) ? 1 : -1;
        e->pause = 0;
    }
    RAM.enemy_count = n;
}

/* ---- drawing ----------------------------------------------------------- */

static u16 column_cells[ROWS];

static void draw_column(s16 col)
{
    u8 g = (col >= 0 && (u16)col < level_cols()) ? RAM.ground[col] : 4;
    u16 h = g & GROUND_HEIGHT;
    s16 top = ROWS - h; /* first ground row (ROWS when a pit) */
    u16 row, i;
    for (row = 0; row < ROWS; row++) {
        u16 t = T_BLANK;
        if ((s16)row == top)
            t = T_GRASS;
        else if ((s16)row > top)
            t = (s16)row < top + 3 ? T_DIRT : T_DIRT_DEEP;
        else if (h && (g & GROUND_SPIKES) && (s16)row == top - 1)
            t = T_SPIKES;
        column_cells[row] = TILE_ATTR(PAL_TERRAIN, 0, 0, t);
    }
    for (i = 0; i < RAM.ring_count; i++)
        if (RAM.rings[i].col == col && !RAM.rings[i].taken)
            column_cells[RAM.rings[i].row] = TILE_ATTR(PAL_TERRAIN, 0, 0, T_RING);
    if (col == (s16)(RAM.end_x >> 3) && h >= 1 && top >= 6) { /* goal post */
        for (row = top - 4; (s16)row < top; row++)
            column_cells[row] = TILE_ATTR(PAL_TERRAIN, 0, 0, T_POLE);
        column_cells[top - 5] = TILE_ATTR(PAL_TERRAIN, 0, 0, T_SIGN);
    }
    /* Write the column top to bottom: auto-increment one plane row. */
    vdp_set_reg(15, PLANE_W * 2);
    vdp_vram_write_addr(VRAM_PLANE_A + ((col & (PLANE_W - 1)) << 1));
    for (row = 0; row < ROWS; row++)
        VDP_DATA = column_cells[row];
    vdp_set_reg(15, 2);
}

static void draw_view(s16 left)
{
    s16 c;
    for (c = left; c < left + VIEW_COLS; c++)
        draw_column(c);
    RAM.drawn_left = left;
}

/* Background hills: height in cells of each of plane B's 64 columns. */
static const char hills[PLANE_W + 1] =
    "3345665432233455677765443222345566543323456777654322234566554332";

/* Clouds by day, stars by night: (column, row) of each. */
static const u8 sky[][2] = {{3, 4}, {14, 7}, {24, 3}, {37, 6}, {47, 4}, {57, 8}};

/* Plane B, row by row: a dark bar behind the HUD (rows 0-1; the window
 * plane's text is transparent), then sky with clouds (stars at night), then
 * hills.  The title clears the HUD bar afterwards. */
void world_draw_background(u16 zone)
{
    static u16 row_cells[PLANE_W];
    u16 col, row, i;
    vdp_vram_write_addr(VRAM_PLANE_B);
    for (row = 0; row < 32; row++) {
        for (col = 0; col < PLANE_W; col++) {
            u16 h = hills[col] - '0', t = T_BLANK;
            if (row < 2) {
                t = T_HUD_BG;
            } else if (row == ROWS - h) {
                u16 hl = hills[(col - 1) & (PLANE_W - 1)] - '0';
                u16 hr = hills[(col + 1) & (PLANE_W - 1)] - '0';
                t = hl < h ? T_HILL_UP : hr < h ? T_HILL_DOWN : T_HILL;
            } else if (row > ROWS - h && row < ROWS) {
                t = T_HILL;
            }
            row_cells[col] = t;
        }
        for (i = 0; i < sizeof(sky) / sizeof(sky[0]); i++) {
            u16 c = sky[i][0], r = sky[i][1];
            if (zone == 2) {
                if (row == r)
                    row_cells[c] = T_STAR;
                if (row == r + 3)
                    row_cells[c + 5] = T_STAR;
            } else if (row == r) {
                row_cells[c] = T_CLOUD_L;
                row_cells[c + 1] = T_CLOUD_M;
                row_cells[c + 2] = T_CLOUD_R;
            }
        }
        for (col = 0; col < PLANE_W; col++)
            VDP_DATA = TILE_ATTR(PAL_TERRAIN, 0, 0, row_cells[col]);
    }
}

void world_load(u16 zone, u16 act)
{
    const struct level *lv = &levels[zone][act];
    u16 i;
    RAM.start_x = lv->start_x;
    RAM.end_x = lv->end_x;
    expand_terrain(lv);
    expand_rings(lv);
    place_enemies(lv);
    for (i = 0; i < 4; i++)
        RAM.redraw[i] = -1;
    RAM.camera_x = 0;
    art_zone_palette(zone);
    vdp_fill_plane(VRAM_PLANE_A, 0);
    world_draw_background(zone);
    draw_view(0);
}

/* ---- camera ------------------------------------------------------------ */

void world_follow(s16 focus_x)
{
    s16 cam = focus_x - 144;
    s16 max = RAM.level_width - SCREEN_W;
    if (cam > max)
        cam = max;
    if (cam < 0)
        cam = 0;
    RAM.camera_x = cam;
}

void world_redraw(s16 col)
{
    u16 i;
    for (i = 0; i < 4; i++)
        if (RAM.redraw[i] < 0) {
            RAM.redraw[i] = col;
            return;
        }
}

void world_scroll(void)
{
    s16 want = RAM.camera_x >> 3;
    u16 i;
    if (want > RAM.drawn_left + 2 || want < RAM.drawn_left - 2) {
        draw_view(want); /* a jump (respawn): redraw everything */
    } else {
        while (RAM.drawn_left < want) {
            draw_column(RAM.drawn_left + VIEW_COLS);
            RAM.drawn_left++;
        }
        while (RAM.drawn_left > want) {
            RAM.drawn_left--;
            draw_column(RAM.drawn_left);
        }
    }
    for (i = 0; i < 4; i++)
        if (RAM.redraw[i] >= 0) {
            s16 c = RAM.redraw[i];
            if (c >= RAM.drawn_left && c < RAM.drawn_left + VIEW_COLS)
                draw_column(c);
            RAM.redraw[i] = -1;
        }
    vdp_hscroll(-RAM.camera_x, -(RAM.camera_x >> 1));
}
