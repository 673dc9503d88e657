/*
 * The six acts.  Heights are in 8-pixel tiles above the bottom of the
 * screen: 4 is the usual floor (feet at y = 192).  A rise of one tile is a
 * step the player walks up; two or more is a wall to jump.  PIT is a
 * bottomless gap, SPK a run of spikes.  Rings sit in cell rows, 0 = top of
 * the screen: row 22 is picked up running on a height-4 floor, rows above
 * need a jump.
 */
#include "levels.h"
#include "ram.h"

#define G(n, h) {n, h}
#define PIT(n) {n, 0}
#define SPK(n, h) {n, (h) | GROUND_SPIKES}
#define END {0, 0}

/* ---- Zone 1: Green Meadow -------------------------------------------- */
static const struct segment z1a1[] = {
    G(36, 4), PIT(4), G(24, 4), G(8, 5), G(8, 6), G(20, 4), PIT(5), G(18, 4),
    SPK(3, 4), G(22, 4), G(10, 6), G(16, 4), PIT(6), G(60, 4), END};
static const struct ring_line z1a1_rings[] = {
    {14, 22, 4}, {50, 22, 3}, {101, 17, 3}, {150, 19, 4}, {185, 22, 5}, {0, 0, 0}};
static const u16 z1a1_enemies[] = {420, 910, 1320, 0};

static const struct segment z1a2[] = {
    G(30, 4), SPK(2, 4), G(20, 4), PIT(5), G(10, 4), G(10, 7), PIT(4), G(10, 7),
    G(20, 4), PIT(6), G(24, 4), SPK(4, 4), G(16, 4), G(12, 6), G(10, 8), G(12, 4),
    PIT(7), G(20, 4), G(58, 4), END};
static const struct ring_line z1a2_rings[] = {
    {20, 22, 4}, {62, 16, 3}, {78, 18, 3}, {112, 22, 5}, {168, 16, 4},
    {205, 22, 6}, {0, 0, 0}};
static const u16 z1a2_enemies[] = {330, 800, 1030, 1700, 0};

/* ---- Zone 2: Sunset Sands -------------------------------------------- */
static const struct segment z2a1[] = {
    G(28, 4), PIT(5), G(14, 5), PIT(5), G(14, 6), G(24, 4), SPK(3, 4), G(6, 4),
    SPK(3, 4), G(20, 4), G(8, 6), G(8, 8), PIT(6), G(8, 8), G(20, 4), PIT(8),
    G(26, 4), SPK(5, 4), G(20, 4), G(12, 7), G(16, 4), PIT(6), G(70, 4), END};
static const struct ring_line z2a1_rings[] = {
    {10, 22, 5}, {34, 18, 4}, {54, 17, 4}, {92, 22, 6}, {128, 13, 4},
    {160, 19, 5}, {200, 16, 3}, {230, 17, 8}, {0, 0, 0}};
static const u16 z2a1_enemies[] = {470, 620, 900, 1300, 1540, 2000, 0};

static const struct segment z2a2[] = {
    G(26, 4), G(6, 6), PIT(6), G(6, 6), G(20, 4), SPK(4, 4), G(16, 4), PIT(7),
    G(12, 4), G(10, 7), G(10, 9), PIT(5), G(10, 7), G(22, 4), SPK(2, 4), G(4, 4),
    SPK(2, 4), G(4, 4), SPK(2, 4), G(24, 4), PIT(8), G(14, 5), PIT(6), G(30, 4),
    G(8, 6), G(24, 4), PIT(7), G(76, 4), END};
static const struct ring_line z2a2_rings[] = {
    {12, 22, 5}, {34, 16, 4}, {62, 22, 4}, {104, 13, 4}, {150, 22, 4},
    {176, 16, 4}, {214, 22, 8}, {262, 19, 4}, {300, 22, 6}, {0, 0, 0}};
static const u16 z2a2_enemies[] = {430, 1190, 1480, 1700, 1930, 2200, 0};

/* ---- Zone 3: Crystal Night ------------------------------------------- */
static const struct segment z3a1[] = {
    G(24, 4), PIT(6), G(10, 4), PIT(6), G(10, 4), G(8, 6), G(8, 8), G(8, 10),
    PIT(6), G(10, 6), G(20, 4), SPK(6, 4), G(16, 4), PIT(8), G(16, 4), G(10, 7),
    PIT(5), G(10, 7), PIT(5), G(10, 7), G(24, 4), SPK(3, 4), G(5, 4), SPK(3, 4),
    G(5, 4), SPK(3, 4), G(24, 4), PIT(9), G(30, 4), G(12, 6), G(20, 4), PIT(7),
    G(78, 4), END};
static const struct ring_line z3a1_rings[] = {
    {8, 22, 5}, {30, 17, 4}, {46, 17, 4}, {76, 10, 4}, {112, 22, 6},
    {148, 17, 4}, {170, 13, 6}, {205, 16, 8}, {262, 18, 4}, {300, 22, 6},
    {340, 22, 6}, {0, 0, 0}};
static const u16 z3a1_enemies[] = {850, 1040, 1230, 1710, 2050, 2340, 2640, 0};

static const struct segment z3a2[] = {
    G(22, 4), SPK(3, 4), G(12, 4), PIT(7), G(12, 5), PIT(7), G(12, 6), PIT(7),
    G(16, 4), G(10, 7), G(8, 10), PIT(8), G(10, 6), G(22, 4), SPK(8, 4), G(20, 4),
    PIT(9), G(20, 4), G(8, 6), G(8, 9), G(8, 6), G(20, 4), SPK(3, 4), G(6, 4),
    SPK(3, 4), G(6, 4), SPK(3, 4), G(20, 4), PIT(8), G(8, 6), PIT(8), G(30, 4),
    G(14, 7), G(24, 4), PIT(7), G(80, 4), END};
static const struct ring_line z3a2_rings[] = {
    {10, 22, 4}, {38, 16, 4}, {57, 15, 4}, {76, 14, 4}, {124, 10, 4},
    {150, 22, 6}, {174, 13, 8}, {234, 12, 4}, {282, 16, 4}, {330, 16, 6},
    {380, 22, 8}, {0, 0, 0}};
static const u16 z3a2_enemies[] = {720, 1160, 1390, 1620, 1980, 2700, 2870, 3020, 0};

const struct level levels[ZONES][ACTS] = {
    {{48, 1600, z1a1, z1a1_rings, z1a1_enemies},
     {48, 2000, z1a2, z1a2_rings, z1a2_enemies}},
    {{48, 2400, z2a1, z2a1_rings, z2a1_enemies},
     {48, 2640, z2a2, z2a2_rings, z2a2_enemies}},
    {{48, 2960, z3a1, z3a1_rings, z3a1_enemies},
     {48, 3200, z3a2, z3a2_rings, z3a2_enemies}},
};

const char *const zone_names[ZONES] = {
    "GREEN MEADOW", "SUNSET SANDS", "CRYSTAL NIGHT"};
