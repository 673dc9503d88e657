/*
 * Tiles, sprites and palettes, drawn as text: one character per pixel,
 * '.' = transparent / colour 0, '1'-'F' = a colour of the tile's palette.
 * _Static_assert checks every drawing has the right number of pixels.
 */
#include "art.h"
#include "vdp.h"

#define RGB(r, g, b) (((b) << 9) | ((g) << 5) | ((r) << 1)) /* 0-7 each */
#define TILE(name) static const char name[]
#define CHECK8(name) _Static_assert(sizeof(name) == 65, #name " is not 8x8")
#define CHECK16(name) _Static_assert(sizeof(name) == 257, #name " is not 16x16")

void font_load(void);

/* ---- terrain (palette 0) --------------------------------------------------
 * 1 outline, 2-3 grass, 4-5 dirt, 6-7 spikes, 8-9 ring, A-B hills,
 * C-D clouds, E post, F text. */
TILE(grass) = ".2..2..2" "22.222.2" "22222222" "23232323"
              "33333333" "45444544" "44454445" "44444444";
TILE(dirt) = "44444444" "44544444" "44444454" "45444444"
             "44444444" "44444544" "54444444" "44454444";
TILE(dirt_deep) = "55555555" "55455555" "55555545" "54555555"
                  "55555555" "55555455" "45555555" "55545555";
TILE(spikes) = "...6...6" "...6...6" "..67..67" "..67..67"
               ".667.667" ".667.667" "66776677" "77777777";
TILE(ring) = "..8888.." ".899998." "89....98" "89....98"
             "89....98" "89....98" ".899998." "..8888..";
TILE(pole) = "...EE..." "...EE..." "...EE..." "...EE..."
             "...EE..." "...EE..." "...EE..." "...EE...";
TILE(sign) = ".111111." "18888881" "18999981" "18988981"
             "18988981" "18999981" "18888881" ".111EE1.";
TILE(cloud_l) = "........" "......CC" "....CCCC" "..CCCCCC"
                ".CCCCCCC" "CCCCCCCC" "DDDDDDDD" "........";
TILE(cloud_m) = "..CCCC.." ".CCCCCCC" "CCCCCCCC" "CCCCCCCC"
                "CCCCCCCC" "CCCCCCCC" "DDDDDDDD" "........";
TILE(cloud_r) = "........" "CC......" "CCCC...." "CCCCCC.."
                "CCCCCCC." "CCCCCCCC" "DDDDDDDD" "........";
TILE(hill_up) = ".......A" "......AA" ".....AAA" "....AAAA"
                "...AAAAA" "..AAAAAA" ".AAAAAAA" "AAAAAAAA";
TILE(hill_down) = "A......." "AA......" "AAA....." "AAAA...."
                  "AAAAA..." "AAAAAA.." "AAAAAAA." "AAAAAAAA";
TILE(hill) = "AAAAAAAA" "AABAAAAA" "AAAAAABA" "AAAAAAAA"
             "ABAAAAAA" "AAAABAAA" "AAAAAAAA" "AAAAAAAB";
TILE(star) = "........" "........" "...C...." "..CDC..." "...C...."
             "........" "........" "........";
CHECK8(grass); CHECK8(dirt); CHECK8(dirt_deep); CHECK8(spikes); CHECK8(ring);
CHECK8(pole); CHECK8(sign); CHECK8(cloud_l); CHECK8(cloud_m); CHECK8(cloud_r);
TILE(hud_bg) = "11111111" "11111111" "11111111" "11111111" "11111111"
               "11111111" "11111111" "11111111";
CHECK8(hill_up); CHECK8(hill_down); CHECK8(hill); CHECK8(star); CHECK8(hud_bg);

/* ---- Dasher (palettes 1 and 2): 1 outline, 2-3 body, 4 belly, 5 eye,
 * 6-7 shoes.  Faces right; the sprite is flipped to face left. */
TILE(player_stand) =
    "......1111......" "....11222211...." "...1222222221..." "..122222255551.."
    ".1222222255151.." ".1222222255151.." "1222222222555521" "1222222444444421"
    ".122224444444421" ".12222444444421." "..122224444421.." "...11222222211.."
    "....12211221...." "...1667116671..." "..166667166667.." "..111111111111..";
TILE(player_run1) =
    "......1111......" "....11222211...." "...1222222221..." "..122222255551.."
    ".1222222255151.." ".1222222255151.." "1222222222555521" "1222222444444421"
    ".122224444444421" ".12222444444421." "..122224444421.." "...11222222211.."
    "...122111221...." "..16671.12221..." ".166661..166671." ".111111..111111.";
TILE(player_run2) =
    "......1111......" "....11222211...." "...1222222221..." "..122222255551.."
    ".1222222255151.." ".1222222255151.." "1222222222555521" "1222222444444421"
    ".122224444444421" ".12222444444421." "..122224444421.." "...11222222211.."
    ".....1221221...." "....16671671...." "...16666716671.." "...11111111111..";
TILE(player_ball) =
    ".....111111....." "...1122222211..." "..122222222221.." ".12223222232221."
    ".12222322322221." "1222222332222221" "1222223223222221" "1222232222322221"
    "1222222222222221" "1222222332222221" "1222223223222221" ".12222322322221."
    ".12223222232221." "..122222222221.." "...1122222211..." ".....111111.....";
CHECK16(player_stand); CHECK16(player_run1); CHECK16(player_run2); CHECK16(player_ball);

/* ---- Crawler (palette 3): 1 outline, 2-3 shell, 4 eye, 5 white, 6 legs. */
TILE(enemy1) =
    "................" "................" "................" "................"
    "......1111......" "....11222211...." "...1222222221..." "..1225222222221."
    "..1554122222221." ".12222222222221." ".13333333333331." ".11111111111111."
    "..16.16..61.61.." "..16.16..61.61.." ".16..16..61..61." ".1...1....1...1.";
TILE(enemy2) =
    "................" "................" "................" "......1111......"
    "....11222211...." "...1222222221..." "..1225222222221." "..1554122222221."
    ".12222222222221." ".13333333333331." ".11111111111111." "...16.16..61.61."
    "...16.16..61.61." "...16.16..61.61." "..16..16..61.61." "..1...1....1..1.";
CHECK16(enemy1); CHECK16(enemy2);

/* ---- palettes ------------------------------------------------------------ */
static const u16 zone_palettes[3][16] = {
    { /* Zone 1, Green Meadow: blue sky, green grass, brown earth */
      RGB(2, 4, 7), RGB(0, 0, 0), RGB(2, 6, 1), RGB(1, 4, 0),
      RGB(6, 4, 2), RGB(4, 2, 1), RGB(6, 6, 6), RGB(3, 3, 3),
      RGB(7, 7, 0), RGB(6, 4, 0), RGB(1, 5, 3), RGB(0, 3, 2),
      RGB(7, 7, 7), RGB(5, 5, 6), RGB(5, 5, 5), RGB(7, 7, 7) },
    { /* Zone 2, Sunset Sands: orange sky, sand, red rock */
      RGB(7, 4, 2), RGB(0, 0, 0), RGB(7, 6, 2), RGB(6, 4, 1),
      RGB(5, 3, 1), RGB(3, 2, 0), RGB(6, 6, 6), RGB(3, 3, 3),
      RGB(7, 7, 0), RGB(6, 4, 0), RGB(6, 3, 1), RGB(4, 2, 1),
      RGB(7, 6, 4), RGB(7, 5, 3), RGB(5, 5, 5), RGB(7, 7, 7) },
    { /* Zone 3, Crystal Night: dark sky, violet crystal, slate */
      RGB(1, 0, 3), RGB(0, 0, 0), RGB(5, 2, 7), RGB(3, 1, 5),
      RGB(2, 2, 3), RGB(1, 1, 2), RGB(6, 6, 6), RGB(3, 3, 3),
      RGB(7, 7, 0), RGB(6, 4, 0), RGB(2, 1, 4), RGB(1, 0, 2),
      RGB(6, 6, 7), RGB(3, 3, 5), RGB(5, 5, 5), RGB(7, 7, 7) },
};

static const u16 p1_palette[16] = {
    0, RGB(0, 0, 0), RGB(1, 2, 7), RGB(0, 1, 4), RGB(7, 5, 3), RGB(7, 7, 7),
    RGB(7, 1, 1), RGB(4, 0, 0), 0, 0, 0, 0, 0, 0, 0, RGB(7, 7, 7) };
static const u16 p2_palette[16] = {
    0, RGB(0, 0, 0), RGB(7, 4, 0), RGB(5, 2, 0), RGB(7, 6, 4), RGB(7, 7, 7),
    RGB(1, 6, 1), RGB(0, 3, 0), 0, 0, 0, 0, 0, 0, 0, RGB(7, 7, 7) };
static const u16 enemy_palette[16] = {
    0, RGB(0, 0, 0), RGB(6, 0, 5), RGB(3, 0, 3), RGB(7, 7, 0), RGB(7, 7, 7),
    RGB(4, 4, 4), 0, 0, 0, 0, 0, 0, 0, 0, RGB(7, 7, 0) };

void art_zone_palette(u16 zone)
{
    vdp_set_palette(PAL_TERRAIN, zone_palettes[zone < 3 ? zone : 0]);
}

void art_load(void)
{
    static const char *const terrain[] = {
        grass, dirt, dirt_deep, spikes, ring, pole, sign,
        cloud_l, cloud_m, cloud_r, hill_up, hill_down, hill, star, hud_bg,
    };
    u16 i;
    for (i = 0; i < sizeof(terrain) / sizeof(terrain[0]); i++)
        vdp_load_tile(T_GRASS + i, terrain[i]);
    font_load();
    vdp_load_sprite16(T_PLAYER + 4 * PLAYER_STAND, player_stand);
    vdp_load_sprite16(T_PLAYER + 4 * PLAYER_RUN1, player_run1);
    vdp_load_sprite16(T_PLAYER + 4 * PLAYER_RUN2, player_run2);
    vdp_load_sprite16(T_PLAYER + 4 * PLAYER_BALL, player_ball);
    vdp_load_sprite16(T_ENEMY, enemy1);
    vdp_load_sprite16(T_ENEMY + 4, enemy2);
    art_zone_palette(0);
    vdp_set_palette(PAL_P1, p1_palette);
    vdp_set_palette(PAL_P2, p2_palette);
    vdp_set_palette(PAL_ENEMY, enemy_palette);
}
