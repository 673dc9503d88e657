/* The three levels: each longer, with wider pits, taller steps and more crawlers.
 * A jump clears about 90 pixels (11 columns) at full speed and rises 6 tiles. */
#include "levels.h"

static const unsigned char runs1[] = {
    20, 4,  4, 0,  16, 4,  8, 5,  10, 4,  5, 0,  14, 4,  6, 6,
    12, 4,  4, 0,  10, 4,  8, 5,  16, 4,  5, 0,  22, 4,  0};
static const unsigned char crawlers1[] = {26, 37,  65, 74,  119, 130,  0};
static const unsigned char coins1[] = {
    12, 24,  13, 24,  14, 24,  15, 24,  21, 19,  22, 19,  59, 18,  60, 18,  100, 24,  101, 24,  0};

static const unsigned char runs2[] = {
    16, 4,  5, 0,  12, 4,  6, 6,  14, 4,  5, 0,  10, 5,  4, 0,  12, 5,  8, 4,
    6, 0,  18, 4,  6, 7,  12, 4,  5, 0,  16, 4,  6, 0,  14, 4,  25, 4,  0};
static const unsigned char crawlers2[] = {23, 31,  41, 46,  100, 113,  124, 131,  163, 172,  0};
static const unsigned char coins2[] = {
    18, 19,  19, 19,  20, 19,  40, 16,  41, 16,  76, 23,  77, 23,  110, 24,  111, 24,  150, 18,  151, 18,  0};

static const unsigned char runs3[] = {
    14, 4,  6, 0,  10, 4,  6, 6,  4, 8,  10, 4,  6, 0,  12, 5,  6, 0,  12, 4,
    8, 6,  10, 4,  7, 0,  14, 4,  6, 7,  12, 5,  6, 0,  16, 4,  6, 0,  10, 4,
    7, 0,  20, 4,  32, 4,  0};
static const unsigned char crawlers3[] = {21, 28,  58, 65,  76, 83,  112, 122,  150, 162,  190, 204,  0};
static const unsigned char coins3[] = {
    17, 20,  18, 20,  36, 16,  37, 16,  60, 23,  61, 23,  98, 17,  99, 17,  129, 18,  130, 18,  186, 24,  187, 24,  0};

const struct level levels[LEVELS] = {
    {runs1, crawlers1, coins1, 1200},
    {runs2, crawlers2, coins2, 1520},
    {runs3, crawlers3, coins3, 1840},
};
