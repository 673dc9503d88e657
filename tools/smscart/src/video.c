/* The VDP (mode 4), palettes, tiles drawn as text, and the pads. */
#include "hopper.h"

__sfr __at 0xBE VDP_DATA;
__sfr __at 0xBF VDP_CTRL;
__sfr __at 0xDC PORT_A;  /* pad 1, and pad 2's up/down */
__sfr __at 0xDD PORT_B;  /* pad 2's left/right/buttons */
__sfr __at 0x00 GG_START; /* Game Gear: bit 7 clear while START is held */

#define NAME_TABLE 0x3800
#define SAT_VRAM 0x3F00

/* Colours as 12-bit 0xBGR (the Game Gear's format); the Master System keeps
 * the top two bits of each component, as --BBGGRR. */
#if CONSOLE_GG
typedef uint16_t Colour;
#define C(bgr) (bgr)
#else
typedef uint8_t Colour;
#define C(bgr) ((((bgr) >> 10) & 3) << 4 | (((bgr) >> 6) & 3) << 2 | (((bgr) >> 2) & 3))
#endif

static const Colour palette[32] = {
    /* background: sky, grass, dirt, dark dirt, coin, white, black, coin shade */
    C(0xFA5), C(0x0C4), C(0x26A), C(0x148), C(0x0EF), C(0xFFF), C(0x000), C(0x07C),
    C(0xFFF), C(0xFFF), C(0xFFF), C(0xFFF), C(0xFFF), C(0xFFF), C(0xFFF), C(0xFFF),
    /* sprites: -, player 1 blue, player 2 orange, skin, yellow, white, black, crawler purple, flag red */
    C(0x000), C(0xF40), C(0x07F), C(0x9BF), C(0x0EF), C(0xFFF), C(0x000), C(0xA3A),
    C(0x00F), C(0xFFF), C(0xFFF), C(0xFFF), C(0xFFF), C(0xFFF), C(0xFFF), C(0xFFF),
};
static const Colour skies[4] = {C(0xFA5), C(0x58F), C(0x844), C(0x420)};

/* Each tile is 8 rows of 8 pixels, one hex digit a pixel ('.' = 0). */
static const char tiles[][65] = {
    "........" "........" "........" "........" "........" "........" "........" "........",
    "11111111" "11111111" "21121112" "22222222" "22232222" "22222222" "23222232" "22222222",
    "22222222" "22322222" "22222232" "22222222" "22222222" "32222222" "22222322" "22222222",
    "........" "..4444.." ".447744." ".447744." ".447744." ".447744." "..4444.." "........",
    "..1111.." ".111111." ".133331." ".136361." ".133331." "..3333.." ".111111." "11111111",
    "11111111" ".111111." ".111111." ".111111." "..1..1.." "..1..1.." ".66..66." ".66..66.",
    "..2222.." ".222222." ".233332." ".236362." ".233332." "..3333.." ".222222." "22222222",
    "22222222" ".222222." ".222222." ".222222." "..2..2.." "..2..2.." ".66..66." ".66..66.",
    "........" "..7777.." ".777777." "75577557" "76577657" "77777777" "77777777" ".6.6.6.6",
    "........" "..7777.." ".777777." "75577557" "75677567" "77777777" "77777777" "6.6.6.6.",
    "8888888." "88888888" "8888888." "6......." "6......." "6......." "6......." "6.......",
};

/* A small font, one byte a row (bit 7 = left), for the title and the HUD. */
static const char glyph_chars[] = "0123456789ABCDEGHLMNOPRSTUVY";
static const uint8_t glyphs[][8] = {
    {0x3C, 0x66, 0x6E, 0x76, 0x66, 0x66, 0x3C, 0}, {0x18, 0x38, 0x18, 0x18, 0x18, 0x18, 0x7E, 0},
    {0x3C, 0x66, 0x06, 0x1C, 0x30, 0x60, 0x7E, 0}, {0x3C, 0x66, 0x06, 0x1C, 0x06, 0x66, 0x3C, 0},
    {0x0C, 0x1C, 0x3C, 0x6C, 0x7E, 0x0C, 0x0C, 0}, {0x7E, 0x60, 0x7C, 0x06, 0x06, 0x66, 0x3C, 0},
    {0x3C, 0x60, 0x7C, 0x66, 0x66, 0x66, 0x3C, 0}, {0x7E, 0x06, 0x0C, 0x18, 0x30, 0x30, 0x30, 0},
    {0x3C, 0x66, 0x66, 0x3C, 0x66, 0x66, 0x3C, 0}, {0x3C, 0x66, 0x66, 0x3E, 0x06, 0x0C, 0x38, 0},
    {0x18, 0x3C, 0x66, 0x66, 0x7E, 0x66, 0x66, 0}, {0x7C, 0x66, 0x66, 0x7C, 0x66, 0x66, 0x7C, 0},
    {0x3C, 0x66, 0x60, 0x60, 0x60, 0x66, 0x3C, 0}, {0x78, 0x6C, 0x66, 0x66, 0x66, 0x6C, 0x78, 0},
    {0x7E, 0x60, 0x60, 0x7C, 0x60, 0x60, 0x7E, 0}, {0x3C, 0x66, 0x60, 0x6E, 0x66, 0x66, 0x3E, 0},
    {0x66, 0x66, 0x66, 0x7E, 0x66, 0x66, 0x66, 0}, {0x60, 0x60, 0x60, 0x60, 0x60, 0x60, 0x7E, 0},
    {0x63, 0x77, 0x7F, 0x6B, 0x63, 0x63, 0x63, 0},
    {0x66, 0x76, 0x7E, 0x7E, 0x6E, 0x66, 0x66, 0}, {0x3C, 0x66, 0x66, 0x66, 0x66, 0x66, 0x3C, 0},
    {0x7C, 0x66, 0x66, 0x7C, 0x60, 0x60, 0x60, 0}, {0x7C, 0x66, 0x66, 0x7C, 0x6C, 0x66, 0x66, 0},
    {0x3C, 0x66, 0x60, 0x3C, 0x06, 0x66, 0x3C, 0}, {0x7E, 0x18, 0x18, 0x18, 0x18, 0x18, 0x18, 0},
    {0x66, 0x66, 0x66, 0x66, 0x66, 0x66, 0x3C, 0}, {0x66, 0x66, 0x66, 0x66, 0x66, 0x3C, 0x18, 0},
    {0x66, 0x66, 0x66, 0x3C, 0x18, 0x18, 0x18, 0},
};

static void vram_address(uint16_t address, uint8_t code)
{
    VDP_CTRL = address & 0xFF;
    VDP_CTRL = (address >> 8) | code;
}

void vdp_set_reg(uint8_t reg, uint8_t value)
{
    VDP_CTRL = value;
    VDP_CTRL = 0x80 | reg;
}

static void load_colour(uint8_t index, Colour c)
{
#if CONSOLE_GG
    vram_address(index * 2, 0xC0);
    VDP_DATA = c & 0xFF;   /* the Game Gear latches the low byte, then writes the word */
    VDP_DATA = c >> 8;
#else
    vram_address(index, 0xC0);
    VDP_DATA = c;
#endif
}

void vdp_set_sky(uint8_t level)
{
    load_colour(0, skies[level & 3]);
}

/* Write one tile's four bit planes, each row's pixel values taken from
 * ``pixels`` (hex digits) or, for a glyph, ``colour`` where its bit is set. */
static void load_tile(uint8_t tile, const char *pixels, const uint8_t *rows, uint8_t colour)
{
    uint8_t y, x, v, mask, b0, b1, b2, b3;
    vram_address((uint16_t)tile * 32, 0x40);
    for (y = 0; y < 8; y++) {
        b0 = b1 = b2 = b3 = 0;
        for (x = 0, mask = 0x80; x < 8; x++, mask >>= 1) {
            if (pixels) {
                char ch = *pixels++;
                v = ch == '.' ? 0 : ch <= '9' ? ch - '0' : ch - 'a' + 10;
            } else {
                v = (rows[y] & mask) ? colour : 0;
            }
            if (v & 1) b0 |= mask;
            if (v & 2) b1 |= mask;
            if (v & 4) b2 |= mask;
            if (v & 8) b3 |= mask;
        }
        VDP_DATA = b0;
        VDP_DATA = b1;
        VDP_DATA = b2;
        VDP_DATA = b3;
    }
}

void vdp_clear_map(void)
{
    uint8_t i = 0;
    vram_address(NAME_TABLE, 0x40);
    do {  /* 32 x 28 entries of 2 bytes: 7 rounds of 256 */
        VDP_DATA = 0; VDP_DATA = 0; VDP_DATA = 0; VDP_DATA = 0; VDP_DATA = 0; VDP_DATA = 0; VDP_DATA = 0;
    } while (++i);
}

void vdp_init(void)
{
    uint8_t i;
    static const uint8_t regs[11] = {
        0x26,  /* mode 4, blank the leftmost column (garbage from scrolling) */
        0xA0,  /* display off, frame interrupts on, 8x8 sprites */
        0xFF,  /* name table at 0x3800 */
        0xFF, 0xFF,
        0xFF,  /* sprite table at 0x3F00 */
        0xFB,  /* sprite tiles from 0x0000 */
        0x00,  /* border colour: sprite palette 0 */
        0x00, 0x00,
        0xFF,  /* no line interrupts */
    };
    for (i = 0; i < 11; i++)
        vdp_set_reg(i, regs[i]);
    for (i = 0; i < 32; i++)
        load_colour(i, palette[i]);
    for (i = 0; i < sizeof(tiles) / sizeof(tiles[0]); i++)
        load_tile(i, tiles[i], 0, 0);
    for (i = 0; i < sizeof(glyph_chars) - 1; i++)
        load_tile(glyph_chars[i], 0, glyphs[i], 5);
    vdp_clear_map();
    G.sat[0] = 0xD0;
    vdp_upload_sat();
}

void vdp_display(uint8_t on)
{
    vdp_set_reg(1, on ? 0xE0 : 0xA0);
}

void vdp_put_tile(uint8_t col, uint8_t row, uint8_t tile)
{
    vram_address(NAME_TABLE + ((uint16_t)row << 6) + ((col & 31) << 1), 0x40);
    VDP_DATA = tile;
    VDP_DATA = 0;
}

void vdp_text(uint8_t col, uint8_t row, const char *text)
{
    while (*text)
        vdp_put_tile(col++, row, (uint8_t)*text++);
}

void vdp_upload_sat(void)
{
    uint8_t i;
    vram_address(SAT_VRAM, 0x40);
    for (i = 0; i < 64; i++)
        VDP_DATA = G.sat[i];
    vram_address(SAT_VRAM + 0x80, 0x40);
    for (i = 64; i < 192; i++)
        VDP_DATA = G.sat[i];
}

void wait_vblank(void)
{
    uint8_t seen = G.vblanks;
    while (G.vblanks == seen)
        ;
}

/* Pads are active low. The PAUSE button (Master System) only raises an NMI,
 * which crt0.s records in G.pause; it counts as pad 1's START. */
void read_pads(void)
{
    uint8_t a = ~PORT_A, p1, p2 = 0;
    p1 = a & 0x3F;
#if CONSOLE_GG
    if (!(GG_START & 0x80))
        p1 |= PAD_START;
#else
    {
        uint8_t b = ~PORT_B;
        p2 = (a >> 6) | ((b & 0x0F) << 2);
    }
    if (G.pause) {
        p1 |= PAD_START;
        G.pause = 0;
    }
#endif
    G.pad1_new = p1 & ~G.pad1;
    G.pad2_new = p2 & ~G.pad2;
    G.pad1 = p1;
    G.pad2 = p2;
}
