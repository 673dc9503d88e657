"""Trekker, our Game Boy cartridge, on the real gambatte core through retrokit's host.

The game is documented in tools/gbcart/README.md; one source builds games/Trekker-GameBoy/rom.gb
and games/Trekker-GbColor/rom.gbc, whose game.yaml files are checked here against
tools/gbcart/src/ram.h. The byte-for-byte rebuild is tests/test_cartridges.py's, and every
retrokit tool on both ROMs is tests/test_systems.py's: this file tests the game itself, and the
facts of the core that the GameBoy and GbColor descriptors in host/systems.yaml rely on.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from cartgame import ALIVE, DYING, CartGame, game_fields, lose_every_life, ram_h_fields, run_into_goal, start_selected

REPO = Path(__file__).resolve().parent.parent
CART_DIR = REPO / "tools" / "gbcart"
ROMS = {
    "GameBoy": REPO / "games" / "Trekker-GameBoy" / "rom.gb",
    "GbColor": REPO / "games" / "Trekker-GbColor" / "rom.gbc",
}
# The levels' goal x, from tools/gbcart/src/levels.c: 10 columns before each level's end.
END_X = {0: 1184, 1: 1200, 2: 1280}
FIRST_PIT = (176, 200)  # level 1's first pit, x 176-199 (columns 22-24)
COIN_X = 228  # level 1's first coin, above column 28

FIELDS = game_fields(ROMS["GameBoy"].parent)


class Trekker(CartGame):
    """An emulator running Trekker, with the game's fields by name."""

    def __init__(self, system: str = "GameBoy") -> None:
        super().__init__(ROMS[system], FIELDS)

    def walker(self, index: int) -> tuple[int, int]:
        """A walker's x and state (0 gone, 1 walking, 2 paused)."""
        base = 0xC040 + 8 * index
        return self.emu.peek(base, "<u2"), self.emu.peek(base + 6)

    def close(self) -> None:
        assert self["crash"] == 0, "the CPU ran into erased ROM (rst 0x38)"
        super().close()


@pytest.fixture
def trekker():
    game = Trekker()
    game.boot()
    yield game
    game.close()


@pytest.fixture
def playing(trekker: Trekker) -> Trekker:
    trekker.start()
    return trekker


# --- the ROMs and their data files -------------------------------------------------------------


@pytest.mark.parametrize("system", ROMS)
def test_game_yaml_addresses_match_the_source(system: str) -> None:
    fields = game_fields(ROMS[system].parent)
    assert fields == FIELDS, "both builds share one RAM map"
    known = ram_h_fields(CART_DIR / "src" / "ram.h")
    assert set(fields) <= set(known), f"game.yaml fields not in src/ram.h: {sorted(set(fields) - set(known))}"
    assert {name: address for name, (address, _) in fields.items()} == {name: known[name] for name in fields}
    assert fields["p1_x"][1] == "<i2" and fields["p1_score"][1] == "<d4" and fields["p1_lives"][1] == "|u1"
    assert yaml.safe_load((ROMS[system].parent / "game.yaml").read_text())["players"] == 1


@pytest.mark.parametrize("system,cgb_flag", [("GameBoy", 0x00), ("GbColor", 0x80)])
def test_header_checksums_and_cgb_flag(system: str, cgb_flag: int) -> None:
    rom = ROMS[system].read_bytes()
    assert len(rom) == 32 * 1024 and rom[0x147:0x149] == b"\x00\x00", "32 KiB, no mapper"
    assert rom[0x100:0x104] == b"\x00\xc3\x50\x01", "nop; jp 0x150"
    assert rom[0x134:0x13B] == b"TREKKER"
    assert rom[0x143] == cgb_flag
    check = 0
    for byte in rom[0x134:0x14D]:
        check = (check - byte - 1) & 0xFF
    assert rom[0x14D] == check, "the boot ROM refuses a cartridge whose header checksum is wrong"
    total = (sum(rom) - rom[0x14E] - rom[0x14F]) & 0xFFFF
    assert int.from_bytes(rom[0x14E:0x150], "big") == total
    other = ROMS["GbColor" if system == "GameBoy" else "GameBoy"].read_bytes()
    assert rom[0x104:0x134] == other[0x104:0x134], "one Nintendo logo in both builds"


# --- the core: what the GameBoy and GbColor descriptors rely on --------------------------------


@pytest.mark.parametrize("system,wram", [("GameBoy", 8 * 1024), ("GbColor", 32 * 1024)])
def test_gambatte_memory_is_work_ram_at_0xc000_and_hram_through_its_map(system: str, wram: int) -> None:
    game = Trekker(system)
    try:
        game.boot()
        game.start()
        game.run(["RIGHT"], frames=20)
        # RETRO_MEMORY_SYSTEM_RAM is work RAM from 0xC000 (every bank on a GBC); no HRAM in it.
        ram = game.emu.ram
        assert len(ram) == wram
        assert bytes(ram[:0x2000]) == bytes(game.emu.peek(0xC000 + i) for i in range(0x2000))
        assert game.emu.system.ram_base == 0xC000 and game.emu.system.ram_swap == 1
        # HRAM (and IE) are reached through the core's memory map: the OAM DMA routine the boot
        # code copied to 0xFF80 (ld a, 0xC2; ldh (0x46), a), and IE = VBlank only.
        assert [game.emu.peek(0xFF80 + i) for i in range(4)] == [0x3E, 0xC2, 0xE0, 0x46]
        assert game.emu.peek(0xFFFF) == 0x01
        info = game.emu.av_info()
        assert (info["base_height"], info["base_width"]) == (144, 160) == game.emu.screen_shape()
        assert info["fps"] == pytest.approx(game.emu.system.frame_rate(info["fps"]), abs=1e-3)
        assert game["hw_cgb"] == (system == "GbColor"), "gambatte runs a CGB-flagged ROM as a Game Boy Color"
        assert game["color_build"] == (system == "GbColor")
    finally:
        game.close()


@pytest.mark.parametrize("system", ROMS)
def test_colour_build_is_in_colour_and_the_game_boy_build_in_four_greys(system: str) -> None:
    game = Trekker(system)
    try:
        game.boot()
        game.start()
        game.run(frames=2)
        pixels = np.unique(game.emu.screen().reshape(-1, 3), axis=0)
        # Grey within RGB565's rounding: green has 6 bits, so gambatte's white is (248, 252, 248).
        grey = bool((np.abs(pixels.astype(int) - pixels[:, :1].astype(int)) <= 4).all())
        if system == "GameBoy":
            assert grey and len(pixels) == 4, pixels
        else:
            assert not grey and len(pixels) > 4, pixels
    finally:
        game.close()


# --- playing -------------------------------------------------------------------------------------


def test_main_loop_follows_vblank(playing: Trekker) -> None:
    frame, vblanks = playing["frame"], playing["vblanks"]
    playing.run(["RIGHT"], frames=60)
    assert playing["frame"] - frame == 60
    assert playing["vblanks"] - vblanks == 60


def test_holding_right_moves_x_and_the_camera(playing: Trekker) -> None:
    assert playing["p1_x"] == playing["start_x"]
    screen = playing.emu.screen()
    playing.run(["RIGHT"], frames=70)
    assert playing["p1_x"] > playing["start_x"] + 100
    assert playing["camera_x"] > 0, "the camera scrolls with the player"
    assert not np.array_equal(playing.emu.screen(), screen)
    right = playing["p1_x"]
    playing.run(["LEFT"], frames=30)
    assert playing["p1_x"] < right


@pytest.mark.parametrize("button", ["A", "B"], ids=["jump-A", "jump-B"])
def test_jumping_over_a_pit_keeps_the_life(playing: Trekker, button: str) -> None:
    left, right = FIRST_PIT
    playing.run_until(lambda: playing["p1_x"] >= left - 24, ["RIGHT"])
    playing.run(["RIGHT", button], frames=16)
    playing.run(["RIGHT"], frames=40)
    assert playing["p1_x"] > right
    assert playing["p1_state"] == ALIVE and playing["p1_lives"] == 3 and playing["p1_deaths"] == 0


def test_a_coin_scores_ten_in_bcd(playing: Trekker) -> None:
    playing["p1_x"] = COIN_X
    playing.run(["A"], frames=20)
    assert playing["p1_coins"] == 1
    assert playing["p1_score"] == 10
    assert playing.emu.peek(0xC02C) == 0x10, "packed BCD, the low byte first"


def test_stomping_a_walker_scores_and_being_walked_into_costs_a_life(playing: Trekker) -> None:
    x, state = playing.walker(0)
    assert state in (1, 2)
    playing["camera_x"] = x - 80
    playing["p1_x"], playing["p1_y"], playing["p1_vy"], playing["p1_on_ground"] = x, 98, 0x100, 0
    playing.run_until(lambda: playing.walker(0)[1] == 0, limit=30)
    assert playing["p1_score"] == 100 and playing["p1_vy"] < 0, "a stomp scores 100 and bounces"
    assert playing["p1_state"] == ALIVE
    x, _ = playing.walker(1)
    floor = 136 - 8 * (playing.emu.peek(0xC100 + x // 8) & 0x0F)
    playing["camera_x"] = x - 80
    playing["p1_x"], playing["p1_y"], playing["p1_vy"], playing["p1_on_ground"] = x, floor, 0, 1
    playing.run()
    assert playing["p1_state"] == DYING and playing["p1_lives"] == 2


def test_walking_into_a_pit_loses_a_life_and_restarts_the_level(playing: Trekker) -> None:
    left, right = FIRST_PIT
    playing.run_until(lambda: playing["p1_state"] == DYING, ["RIGHT"], limit=300)
    assert left - 8 <= playing["p1_x"] <= right + 8
    assert playing["p1_lives"] == 2 and playing["p1_deaths"] == 1
    playing.run_until(lambda: playing["p1_state"] == ALIVE, limit=120)
    assert playing["p1_x"] == playing["start_x"] and playing["camera_x"] == 0
    assert playing["p1_lives"] == 2


def test_losing_every_life_is_game_over_then_the_title(playing: Trekker) -> None:
    lose_every_life(playing)
    assert playing["level"] == 0


def test_reaching_end_x_clears_the_level(playing: Trekker) -> None:
    playing["p1_x"] = playing["end_x"] - 30  # the last stretch of every level is flat ground
    run_into_goal(playing)
    assert playing["p1_score"] == 1000, "the level-clear bonus, and nothing else"
    assert (playing["level"], playing["end_x"], playing["p1_lives"]) == (1, END_X[1], 3)


# --- level select ------------------------------------------------------------------------------


@pytest.mark.parametrize("when", ["at-title", "before-first-frame"])
@pytest.mark.parametrize("level", list(END_X), ids=[f"level{n + 1}" for n in END_X])
def test_writing_level_selects_it(level: int, when: str) -> None:
    game = Trekker()
    try:
        start_selected(game, {"level": level}, when)
        assert game["end_x"] == END_X[level] and game["level_width"] == game["end_x"] + 80
        assert game["enemy_count"] > 0
    finally:
        game.close()


@pytest.mark.parametrize("system", ROMS)
def test_levels_look_different(system: str) -> None:
    skies = []
    for level in END_X:
        game = Trekker(system)
        game.boot()
        game["level"] = level
        game.start()
        game.run(frames=2)
        skies.append(tuple(game.emu.screen()[4, 4]))
        game.close()
    assert len(set(skies)) == 3, skies


# --- determinism and randomness ------------------------------------------------------------------


def _play(start_frame: int, seed: int = 7) -> tuple[list[tuple[int, int]], list[bytes]]:
    """Start on a given frame, then play a fixed pseudo-random input sequence."""
    game = Trekker()
    try:
        game.boot()
        game.run(frames=start_frame)
        game.start()
        rng = np.random.default_rng(seed)
        choices = [["RIGHT"], ["RIGHT", "A"], ["RIGHT", "B"], [], ["LEFT"]]
        snapshots = []
        for i in range(400):
            game.run(choices[rng.choice(5, p=[0.6, 0.15, 0.1, 0.1, 0.05])])
            if i % 100 == 99:
                snapshots.append(bytes(game.emu.ram))
        return [game.walker(i) for i in range(8)], snapshots
    finally:
        game.close()


def test_same_inputs_give_the_same_ram() -> None:
    assert _play(start_frame=10) == _play(start_frame=10)


def test_the_frame_counter_drives_walker_timing() -> None:
    # Pressing START a frame later changes the random pauses, so where the walkers are later on.
    assert _play(start_frame=10)[0] != _play(start_frame=11)[0]


# --- the benchmarks ------------------------------------------------------------------------------


@pytest.mark.parametrize("name,system", [("trekker", "GameBoy"), ("trekker-color", "GbColor")])
def test_benchmark_is_a_built_in_on_shipped_states(name: str, system: str) -> None:
    from retrokit.benchmark.definition import load_benchmark

    benchmark = load_benchmark(name)
    assert benchmark.name == name
    levels = {level.name for level in benchmark.levels()}
    assert levels == {f"Trekker-{system}/Level{n}" for n in (1, 2, 3)}
    for n in (1, 2, 3):
        assert (ROMS[system].parent / f"Level{n}.state").is_file()
