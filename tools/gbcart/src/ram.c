/*
 * The fixed RAM map of ram.h as variables: sdcc places each at its address.
 */
#include <stddef.h>
#define TREKKER_RAM_C
#include "ram.h"

__at(ADDR_LEVEL) uint8_t level;
__at(ADDR_GAME_MODE) uint8_t game_mode;
__at(ADDR_LEVEL_DONE) uint8_t level_done;
__at(ADDR_HW_CGB) uint8_t hw_cgb;
__at(ADDR_FRAME) uint16_t frame_lo;
__at(ADDR_FRAME + 2) uint16_t frame_hi;
__at(ADDR_RNG) uint16_t rng;
__at(ADDR_END_X) uint16_t end_x;
__at(ADDR_START_X) uint16_t start_x;
__at(ADDR_CAMERA_X) uint16_t camera_x;
__at(ADDR_MODE_TIMER) uint16_t mode_timer;
__at(ADDR_VBLANKS) uint16_t vblanks;
__at(ADDR_PAD) uint8_t pad;
__at(ADDR_PAD_NEW) uint8_t pad_new;
__at(ADDR_LEVEL_WIDTH) uint16_t level_width;
__at(ADDR_ENEMY_COUNT) uint8_t enemy_count;
__at(ADDR_COLOR_BUILD) uint8_t color_build;
__at(ADDR_CRASH) uint8_t crash;
__at(ADDR_P1) Player player;
__at(ADDR_ENEMIES) Enemy enemies[ENEMY_MAX];
__at(ADDR_GROUND) uint8_t ground[MAX_COLUMNS];

_Static_assert(offsetof(Player, score) == P_SCORE, "Player matches ram.h");
_Static_assert(offsetof(Player, deaths) == P_DEATHS, "Player matches ram.h");
_Static_assert(offsetof(Player, jump_held) == P_JUMP_HELD, "Player matches ram.h");
_Static_assert(sizeof(Enemy) == 8 && offsetof(Enemy, info) == E_INFO, "Enemy matches ram.h");
