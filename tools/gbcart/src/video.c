/*
 * The screen: tiles drawn as text, palettes, the level's columns, the HUD
 * (the window's one row at the bottom) and the sprites.
 *
 * VRAM is written only while the LCD is off or in VBlank: the main loop
 * prepares a column or a HUD row in RAM and vblank_work() copies it.
 */
#include <string.h>
#include "hw.h"
#include "ram.h"
#include "game.h"

#define rVBK REG(0xFF4F)
#define OAM_SHADOW ((uint8_t *)0xC200)
#define HUD_ROW 17          /* the window shows the last 8 lines */
#define PLAY_ROWS 17        /* rows 0-16 of the BG map are the level */

/* ---- tiles: '.' colour 0, '1'-'3' colours 1-3 ------------------------------ */
static const char art[][65] = {
    /* 0 sky */ "........" "........" "........" "........" "........" "........" "........" "........",
    /* 1 grass */ "11111111" "13111311" "21312131" "22222222" "22232222" "22222232" "23222222" "22222222",
    /* 2 dirt */ "22222222" "22232222" "22222232" "23222222" "22222222" "22222322" "32222222" "22232222",
    /* 3 coin */ "..3333.." ".311113." "31133113" "31311313" "31311313" "31133113" ".311113." "..3333..",
    /* 4 pole */ "...33..." "...33..." "...33..." "...33..." "...33..." "...33..." "...33..." "...33...",
    /* 5 flag */ "...3333." "...31113" "...31113" "...3333." "...33..." "...33..." "...33..." "...33...",
    /* 6 cloud */ "........" "..1111.." ".111111." "11111111" "11111111" ".111111." "........" "........",
    /* 7 unused */ "........" "........" "........" "........" "........" "........" "........" "........",
    /* 8 head */ "..3333.." ".322223." "32211213" "32211213" "32222223" ".321123." "..3333.." ".322223.",
    /* 9 legs */ "32222223" "32222223" ".322223." ".322223." ".33..33." ".3....3." ".3....3." "33....33",
    /* 10 run 1 */ "32222223" "32222223" ".322223." ".322223." ".33.33.." "33..3..." ".....3.." "....33..",
    /* 11 run 2 */ "32222223" "32222223" ".322223." ".322223." "..33.33." "...3..33" "..3....." "..33....",
    /* 12 walker */ "..3333.." ".311113." "31211213" "31111113" "33333333" ".322223." ".3.33.3." "33....33",
    /* 13 walker */ "..3333.." ".311113." "31211213" "31111113" "33333333" ".322223." ".3.33.3." ".33..33.",
};

/* 5x7 glyphs, one byte a row (bit 4 = left). */
static const char FONT_LETTERS[] = "ACDEGKLMOPRSTVWN!";
static const uint8_t font[][7] = {
    {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}, {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}, /* 0 1 */
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}, {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}, /* 2 3 */
    {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}, {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}, /* 4 5 */
    {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}, {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}, /* 6 7 */
    {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}, {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}, /* 8 9 */
    {0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}, {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}, /* A C */
    {0x1E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1E}, {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}, /* D E */
    {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}, {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}, /* G K */
    {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}, {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}, /* L M */
    {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}, {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}, /* O P */
    {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}, {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}, /* R S */
    {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}, {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}, /* T V */
    {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}, {0x11, 0x19, 0x15, 0x13, 0x11, 0x11, 0x11}, /* W N */
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x04},                                             /* ! */
};
_Static_assert(sizeof(font) / 7 == 10 + sizeof(FONT_LETTERS) - 1, "one glyph per digit and letter");

/* Colours as RGB555 (5 bits each, red lowest). */
#define RGB(r, g, b) ((uint16_t)((r) | ((g) << 5) | ((b) << 10)))
static const uint16_t bg_colors[LEVELS][4] = {
    {RGB(20, 26, 31), RGB(10, 26, 8), RGB(20, 12, 4), RGB(3, 3, 6)},   /* meadow: day */
    {RGB(31, 20, 12), RGB(26, 22, 6), RGB(24, 12, 6), RGB(8, 2, 8)},   /* canyon: sunset */
    {RGB(3, 4, 12), RGB(8, 18, 16), RGB(10, 8, 18), RGB(29, 29, 31)},  /* caves: night */
};
static const uint16_t obj_colors[2][4] = {
    {0, RGB(31, 31, 31), RGB(4, 12, 31), RGB(0, 0, 0)},   /* the player */
    {0, RGB(31, 26, 0), RGB(28, 4, 4), RGB(0, 0, 0)},     /* walkers */
};
/* The Game Boy's four greys: the sky darkens level by level. */
static const uint8_t dmg_bgp[LEVELS] = {0xE4, 0xE1, 0xD2}; /* sky white, light, dark grey */

/* What the next VBlank copies into VRAM. */
static uint8_t column_buf[PLAY_ROWS];
static uint8_t column_slot;
static uint8_t column_pending;
static uint8_t hud_buf[20];
static uint8_t hud_pending;
static uint8_t coin_slot, coin_row, coin_pending;

static void load_tile(uint8_t index, const uint8_t *rows, uint8_t lo_mask, uint8_t hi_mask) {
    volatile uint8_t *dst = VRAM_TILES + (uint16_t)index * 16;
    uint8_t r;
    for (r = 0; r < 8; ++r) {
        *dst++ = rows[r] & lo_mask;
        *dst++ = rows[r] & hi_mask;
    }
}

static void load_art(uint8_t index, const char *text) {
    uint8_t rows_lo[8], rows_hi[8];
    uint8_t r, c;
    volatile uint8_t *dst = VRAM_TILES + (uint16_t)index * 16;
    for (r = 0; r < 8; ++r) {
        uint8_t lo = 0, hi = 0;
        for (c = 0; c < 8; ++c) {
            char ch = *text++;
            uint8_t colour = ch == '.' ? 0 : (uint8_t)(ch - '0');
            lo = (uint8_t)(lo << 1) | (colour & 1);
            hi = (uint8_t)(hi << 1) | (colour >> 1);
        }
        rows_lo[r] = lo;
        rows_hi[r] = hi;
    }
    for (r = 0; r < 8; ++r) {
        *dst++ = rows_lo[r];
        *dst++ = rows_hi[r];
    }
}

void lcd_off(void) {
    if (!(rLCDC & LCDC_ON))
        return;
    while (rLY < 144) {} /* turning the LCD off outside VBlank can damage a real one */
    rLCDC = 0;
}

void lcd_on(void) {
    rLCDC = LCDC_ON | LCDC_WIN_9C00 | LCDC_WIN_ON | LCDC_TILES_8000 | LCDC_OBJ_ON | LCDC_BG_ON;
}

void set_palettes(void) {
#ifdef COLOR
    uint8_t i;
    const uint8_t *bytes;
    rBGPI = 0x80; /* palette 0, colour 0, auto-increment */
    bytes = (const uint8_t *)bg_colors[level < LEVELS ? level : 0];
    for (i = 0; i < 8; ++i)
        rBGPD = bytes[i];
    rOBPI = 0x80;
    bytes = (const uint8_t *)obj_colors;
    for (i = 0; i < 16; ++i)
        rOBPD = bytes[i];
#endif
    rBGP = dmg_bgp[level < LEVELS ? level : 0];
    rOBP0 = 0xE0;
    rOBP1 = 0xE4;
}

void video_init(void) {
    uint8_t i;
    uint8_t rows[8];
    lcd_off();
    for (i = 0; i < sizeof(art) / sizeof(art[0]); ++i)
        load_art(i, art[i]);
    for (i = 0; i < sizeof(font) / 7; ++i) {
        uint8_t r;
        for (r = 0; r < 7; ++r)
            rows[r] = (uint8_t)(font[i][r] << 2);
        rows[7] = 0;
        load_tile(TILE_DIGIT + i, rows, 0xFF, 0xFF);
    }
#ifdef COLOR
    rVBK = 1; /* attributes: every tile with palette 0, no flips */
    memset((uint8_t *)BG_MAP, 0, 0x800);
    rVBK = 0;
#endif
    memset((uint8_t *)WIN_MAP, TILE_SKY, 32);
    memset(OAM_SHADOW, 0, 160);
    memset((uint8_t *)0xFE00, 0, 160);
    rSCX = 0;
    rSCY = 0;
    rWX = 7;
    rWY = 136;
    set_palettes();
}

void clear_bg(void) {
    memset((uint8_t *)BG_MAP, TILE_SKY, 32 * 32);
}

static uint8_t glyph(char ch) {
    uint8_t i;
    if (ch >= '0' && ch <= '9')
        return TILE_DIGIT + (uint8_t)(ch - '0');
    for (i = 0; FONT_LETTERS[i]; ++i)
        if (FONT_LETTERS[i] == ch)
            return TILE_LETTER + i;
    return TILE_SKY;
}

/* Write text into the BG map (LCD off only). */
void draw_text(uint8_t row, uint8_t col, const char *text) {
    volatile uint8_t *dst = BG_MAP + (uint16_t)row * 32 + col;
    while (*text)
        *dst++ = glyph(*text++);
}

/* The tiles of one level column, into column_buf. */
static void build_column(uint8_t column) {
    uint8_t g = ground[column];
    uint8_t h = g & 0x0F;
    uint8_t top = PLAY_ROWS - h; /* the grass row; PLAY_ROWS for a pit */
    uint8_t r;
    uint8_t post = (uint16_t)column == (end_x >> 3);
    for (r = 0; r < PLAY_ROWS; ++r) {
        uint8_t t = TILE_SKY;
        if (h && r >= top)
            t = r == top ? TILE_GRASS : TILE_DIRT;
        else if ((r == 2 && (column & 15) == 3) || (r == 4 && (column & 15) == 10) || (r == 3 && (column & 15) == 11))
            t = TILE_CLOUD;
        column_buf[r] = t;
    }
    if ((g & 0x80) && h)
        column_buf[top - 3] = TILE_COIN;
    if (post && h) {
        for (r = 1; r <= 4; ++r)
            column_buf[top - r] = TILE_POLE;
        column_buf[top - 5] = TILE_FLAG;
    }
}

static void copy_column(void) {
    volatile uint8_t *dst = BG_MAP + column_slot;
    uint8_t *src = column_buf;
    uint8_t r = PLAY_ROWS;
    do {
        *dst = *src++;
        dst += 32;
    } while (--r);
}

/* Draw the screen's columns of the level from camera_x (LCD off only). */
void draw_level_screen(void) {
    uint8_t first = (uint8_t)(camera_x >> 3);
    uint8_t i;
    for (i = 0; i < 22; ++i) {
        build_column(first + i);
        column_slot = (first + i) & 31;
        copy_column();
    }
    column_pending = 0;
    coin_pending = 0;
    rSCX = (uint8_t)camera_x;
}

void prepare_column(uint8_t column) {
    build_column(column);
    column_slot = column & 31;
    column_pending = 1;
}

void clear_coin_tile(uint8_t column) {
    coin_slot = column & 31;
    coin_row = PLAY_ROWS - (ground[column] & 0x0F) - 3;
    coin_pending = 1;
}

static void hud_digit(uint8_t at, uint8_t value) {
    hud_buf[at] = TILE_DIGIT + value;
}

void hud_show_score(void) {
    uint8_t i;
    for (i = 0; i < 4; ++i) {
        uint8_t b = player.score[3 - i];
        hud_digit(2 * i, b >> 4);
        hud_digit(2 * i + 1, b & 15);
    }
    hud_buf[8] = TILE_SKY;
    hud_buf[9] = glyph('L');
    hud_digit(10, player.lives > 9 ? 9 : player.lives);
    hud_buf[11] = TILE_SKY;
    hud_buf[12] = glyph('W');
    hud_digit(13, level < LEVELS ? level + 1 : 1);
    hud_buf[14] = TILE_SKY;
    hud_buf[15] = TILE_COIN;
    hud_digit(16, player.coins / 10 % 10);
    hud_digit(17, player.coins % 10);
    hud_buf[18] = TILE_SKY;
    hud_buf[19] = TILE_SKY;
    hud_pending = 1;
}

void hud_message(const char *text) {
    uint8_t i = 0;
    for (; i < 20 && *text; ++i)
        hud_buf[i] = glyph(*text++);
    for (; i < 20; ++i)
        hud_buf[i] = TILE_SKY;
    hud_pending = 1;
}

/* Everything that touches VRAM or OAM, right after the VBlank interrupt. */
void vblank_work(void) {
    oam_dma();
    rSCX = (uint8_t)camera_x;
    if (column_pending) {
        copy_column();
        column_pending = 0;
    } else if (hud_pending) {
        memcpy((uint8_t *)WIN_MAP, hud_buf, 20);
        hud_pending = 0;
    }
    if (coin_pending) {
        BG_MAP[(uint16_t)coin_row * 32 + coin_slot] = TILE_SKY;
        coin_pending = 0;
    }
    if (game_mode == MODE_TITLE)
        BG_MAP[8 * 32 + 12] = TILE_DIGIT + (level < LEVELS ? level + 1 : 1);
}

static uint8_t *sprite(uint8_t *oam, uint8_t y, uint8_t x, uint8_t tile, uint8_t attr) {
    oam[0] = y;
    oam[1] = x;
    oam[2] = tile;
    oam[3] = attr;
    return oam + 4;
}

/* Fill the shadow sprite table for the next VBlank's DMA. */
void build_sprites(void) {
    uint8_t *oam = OAM_SHADOW;
    uint8_t i;
    memset(OAM_SHADOW, 0, 40);
    if (game_mode == MODE_TITLE)
        return;
    if (player.state != PS_OUT && !(player.state == PS_DYING && (player.timer & 4))) {
        int16_t sx = player.x - (int16_t)camera_x + 4; /* OAM x is the left edge + 8 */
        int16_t sy = player.y;                        /* OAM y is the top + 16; the sprite is 16 tall */
        if (sx > 0 && sx < 168 && sy > 0 && sy < 160) {
            uint8_t attr = player.facing ? 0x20 : 0x00;
            uint8_t legs = TILE_LEGS;
            if (!player.on_ground)
                legs = TILE_LEGS + 1;
            else if (player.vx != 0)
                legs = TILE_LEGS + 1 + (((uint8_t)player.x >> 3) & 1);
            oam = sprite(oam, (uint8_t)sy, (uint8_t)sx, TILE_HEAD, attr);
            oam = sprite(oam, (uint8_t)(sy + 8), (uint8_t)sx, legs, attr);
        }
    }
    for (i = 0; i < ENEMY_MAX; ++i) {
        Enemy *e = &enemies[i];
        int16_t sx;
        uint8_t floor;
        if (!e->state)
            continue;
        sx = (int16_t)e->x - (int16_t)camera_x + 4;
        if (sx <= 0 || sx >= 168)
            continue;
        floor = 136 - 8 * (ground[e->x >> 3] & 0x0F);
        /* walkers use OBJ palette 1 on both consoles (DMG bit 4, CGB bits 0-2) */
        oam = sprite(oam, floor + 8, (uint8_t)sx, TILE_WALKER + (((uint8_t)e->x >> 2) & 1), 0x11);
    }
}
