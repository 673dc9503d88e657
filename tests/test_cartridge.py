"""Dasher, our test cartridge, on the real Genesis Plus GX core through retrokit's host.

The game is documented in tools/testcart/README.md; its RAM map is
games/Dasher-Genesis/game.yaml (checked here against tools/testcart/src/ram.h).
Every emulator here runs with the core's 68000 address-error emulation on, so
a misaligned word access in the game would crash it (and set ``crash``).
"""

from __future__ import annotations

import hashlib
import struct
from pathlib import Path

import numpy as np
import pytest
import yaml
from cartgame import (
    ABSENT,
    ALIVE,
    DYING,
    CartGame,
    game_fields,
    lose_every_life,
    ram_h_fields,
    run_into_goal,
    start_selected,
)

REPO = Path(__file__).resolve().parent.parent
GAME_DIR = REPO / "games" / "Dasher-Genesis"
CART_DIR = REPO / "tools" / "testcart"

# The acts' goal x, from tools/testcart/src/levels.c: every act has its own length.
END_X = {(0, 0): 1600, (0, 1): 2000, (1, 0): 2400, (1, 1): 2640, (2, 0): 2960, (2, 1): 3200}
GROUND_MAP = 0xFF0100  # one byte per 8-pixel column: height in tiles, 0 = pit, 0x20 = spikes


FIELDS = game_fields(GAME_DIR)


class Dasher(CartGame):
    """An emulator running Dasher, with the game's fields by name."""

    def __init__(self, rom: Path, *, tmss: bool = False) -> None:
        options = {"genesis_plus_gx_addr_error": "enabled"}
        if tmss:
            options["genesis_plus_gx_bios"] = "enabled"
        super().__init__(rom, FIELDS, options)

    def ground(self, x: int) -> int:
        return self.emu.peek(GROUND_MAP + x // 8)

    def close(self) -> None:
        assert self["crash"] == 0, f"the 68000 took exception vector {self['crash']}"
        super().close()


@pytest.fixture
def dasher(dasher_rom: Path):
    game = Dasher(dasher_rom)
    game.boot()
    yield game
    game.close()


@pytest.fixture
def playing(dasher: Dasher) -> Dasher:
    dasher.start()
    return dasher


# --- the ROM and its data file ----------------------------------------------------------------


def test_header_is_a_valid_genesis_header(dasher_rom: Path) -> None:
    rom = dasher_rom.read_bytes()
    assert rom[0x100:0x110] in (b"SEGA MEGA DRIVE ", b"SEGA GENESIS    ")
    assert struct.unpack(">I", rom[0x1A0:0x1A4])[0] == 0
    assert struct.unpack(">I", rom[0x1A4:0x1A8])[0] == len(rom) - 1
    assert struct.unpack(">II", rom[0x1A8:0x1B0]) == (0xFF0000, 0xFFFFFF)
    assert rom[0x1F0:0x1F3] == b"JUE"
    words = struct.unpack(f">{(len(rom) - 0x200) // 2}H", rom[0x200:])
    assert struct.unpack(">H", rom[0x18E:0x190])[0] == sum(words) & 0xFFFF
    assert struct.unpack(">I", rom[4:8])[0] == 0x200, "the reset vector points at the boot code"


def test_game_yaml_lists_the_committed_rom(dasher_rom: Path) -> None:
    doc = yaml.safe_load((GAME_DIR / "game.yaml").read_text())
    assert [r["sha1"] for r in doc["roms"]] == [hashlib.sha1(dasher_rom.read_bytes()).hexdigest()]
    assert doc["players"] == 2


def test_game_yaml_addresses_match_the_source() -> None:
    known = ram_h_fields(CART_DIR / "src" / "ram.h")
    for name, (address, _) in FIELDS.items():
        assert name in known, f"game.yaml field {name!r} is not in src/ram.h"
        assert address == known[name], f"{name}: game.yaml says {address:#x}, src/ram.h {known[name]:#x}"
    for name in ("zone", "act", "game_mode", "frame", "end_x", "level_done"):
        assert name in FIELDS
    for player in ("p1", "p2"):
        for name in ("x", "y", "lives", "score", "rings", "state"):
            assert f"{player}_{name}" in FIELDS
    assert FIELDS["p1_x"][1] == ">i2" and FIELDS["p1_lives"][1] == "|u1" and FIELDS["p1_score"][1] == ">d4"


# --- booting ------------------------------------------------------------------------------------


@pytest.mark.parametrize("tmss", [False, True], ids=["tmss-off", "tmss-on"])
def test_boots_to_the_title_and_starts(dasher_rom: Path, tmss: bool) -> None:
    game = Dasher(dasher_rom, tmss=tmss)
    try:
        game.boot()
        version = game["hw_version"]
        assert bool(version & 0x0F) == tmss, f"version register {version:#x}"
        assert game["tmss"] == int(tmss), "the boot code wrote 'SEGA' to 0xA14000 exactly when TMSS is present"
        assert game["selftest"] == 1, "the cartridge's own __mulsi3/__divsi3/... gave wrong answers"
        game.run(frames=30)
        title = game.emu.screen()
        assert len(np.unique(title.reshape(-1, 3), axis=0)) > 4, "the title screen is blank (a locked VDP?)"
        game.start()
        assert (game["zone"], game["act"]) == (0, 0)
        assert game["p1_state"] == ALIVE and game["p1_lives"] == 3
        assert game["p2_state"] == ABSENT
        game.run(frames=5)
        assert not np.array_equal(game.emu.screen(), title)
    finally:
        game.close()


def test_ram_buffer_holds_byte_swapped_words(playing: Dasher) -> None:
    # Genesis Plus GX keeps 68000 RAM as native 16-bit words: on a
    # little-endian host, console address a is at buffer offset (a & 0xFFFF) ^ 1.
    ram = playing.emu.ram
    for name in ("end_x", "level_width"):
        value = playing[name]
        address = FIELDS[name][0] & 0xFFFF
        assert value > 255, "a two-byte value"
        assert (ram[address ^ 1], ram[(address + 1) ^ 1]) == (value >> 8, value & 0xFF)


def test_main_loop_follows_vblank(dasher: Dasher) -> None:
    frame, vblanks = dasher["frame"], dasher["vblanks"]
    dasher.run(frames=60)
    assert dasher["frame"] - frame == 60
    assert (dasher["vblanks"] - vblanks) % 0x10000 == 60


# --- playing ------------------------------------------------------------------------------------


def test_holding_right_moves_x_and_the_camera(playing: Dasher) -> None:
    x = playing["p1_x"]
    assert x == playing["start_x"]
    playing.run(["RIGHT"], frames=90)
    assert playing["p1_x"] > x + 150
    assert playing["camera_x"] > 0, "the camera scrolls with the player"
    right = playing["p1_x"]
    playing.run(["LEFT"], frames=60)
    assert playing["p1_x"] < right


def test_rings_count_and_score_in_bcd(playing: Dasher) -> None:
    # Zone 1 act 1 opens with four rings at head height (x 112-143).
    playing.run(["RIGHT"], frames=60)
    assert playing["p1_rings"] == 4
    assert playing["p1_score"] == 40, "10 points a ring, read as 8 BCD digits"


def _first_pit(game: Dasher) -> tuple[int, int]:
    x = game["p1_x"]
    while game.ground(x) & 0x1F:
        x += 8
    left = x - x % 8
    right = left
    while not game.ground(right) & 0x1F:
        right += 8
    return left, right


@pytest.mark.parametrize("button", ["B", "A", "C"], ids=["jump-B", "jump-A", "jump-C"])
def test_jumping_over_a_pit_keeps_the_life(playing: Dasher, button: str) -> None:
    left, right = _first_pit(playing)
    assert right - left >= 24
    playing.run_until(lambda: playing["p1_x"] >= left - 30, ["RIGHT"])
    playing.run(["RIGHT", button], frames=20)
    playing.run(["RIGHT"], frames=60)
    assert playing["p1_x"] > right
    assert playing["p1_state"] == ALIVE
    assert playing["p1_lives"] == 3
    assert playing["p1_deaths"] == 0


def test_walking_into_a_pit_loses_a_life_and_respawns(playing: Dasher) -> None:
    left, right = _first_pit(playing)
    playing.run_until(lambda: playing["p1_state"] == DYING, ["RIGHT"], limit=400)
    assert left - 8 <= playing["p1_x"] <= right + 8
    assert playing["p1_lives"] == 2
    playing.run_until(lambda: playing["p1_state"] == ALIVE, limit=300)
    assert playing["p1_x"] == playing["start_x"], "a lost life restarts the act from its start"
    assert playing["p1_lives"] == 2


def test_losing_every_life_is_game_over(playing: Dasher) -> None:
    lose_every_life(playing)


def test_reaching_end_x_clears_the_act(playing: Dasher) -> None:
    # Put the player just before the goal (flat ground there) and run in.
    playing["p1_x"] = playing["end_x"] - 40
    run_into_goal(playing)
    assert (playing["zone"], playing["act"]) == (0, 1)
    assert playing["end_x"] == END_X[0, 1]


# --- level select ------------------------------------------------------------------------------


@pytest.mark.parametrize("when", ["at-title", "before-first-frame"])
@pytest.mark.parametrize("zone,act", list(END_X), ids=[f"zone{z + 1}-act{a + 1}" for z, a in END_X])
def test_writing_zone_and_act_selects_the_level(dasher_rom: Path, zone: int, act: int, when: str) -> None:
    game = Dasher(dasher_rom)
    try:
        start_selected(game, {"zone": zone, "act": act}, when)
        assert game["end_x"] == END_X[zone, act]
    finally:
        game.close()


def test_zones_look_different(dasher_rom: Path) -> None:
    skies = []
    for zone in range(3):
        game = Dasher(dasher_rom)
        game.boot()
        game["zone"] = zone
        game.start()
        game.run(frames=2)
        skies.append(tuple(game.emu.screen()[40, 4]))  # sky, below the HUD
        game.close()
    assert len(set(skies)) == 3, skies


# --- two players ---------------------------------------------------------------------------------


def test_port_2_moves_player_2(playing: Dasher) -> None:
    assert playing["p2_state"] == ABSENT
    x1 = playing["p1_x"]
    playing.run(p2=["RIGHT"], frames=60)
    assert playing["p2_state"] == ALIVE, "any button on pad 2 joins player 2"
    assert playing["p2_lives"] == 3
    assert playing["p2_x"] > playing["start_x"] + 20
    assert playing["p1_x"] == x1, "port 2 does not move player 1"
    playing.run_until(lambda: playing["p2_vx"] == 0, limit=120)  # friction stops player 2
    x1, x2 = playing["p1_x"], playing["p2_x"]
    playing.run(["RIGHT"], frames=30)
    assert playing["p2_x"] == x2, "port 1 does not move player 2"
    assert playing["p1_x"] > x1


def test_start_on_port_2_starts_a_two_player_game(dasher: Dasher) -> None:
    dasher.start(p1=[], p2=["START"])
    assert dasher["p1_state"] == ALIVE and dasher["p2_state"] == ALIVE
    dasher.run(p2=["RIGHT", "B"], frames=10)
    assert dasher["p2_vy"] != 0 or dasher["p2_y"] < 192, "player 2 jumps"


# --- determinism and randomness ------------------------------------------------------------------


def _play(rom: Path, start_frame: int, seed: int = 7) -> tuple[bytes, list[bytes]]:
    """Start on a given frame, then play a fixed pseudo-random input sequence."""
    game = Dasher(rom)
    try:
        game.boot()
        game.run(frames=start_frame)
        game.start()
        rng = np.random.default_rng(seed)
        choices = [["RIGHT"], ["RIGHT", "B"], ["RIGHT", "C"], [], ["LEFT"]]
        snapshots = []
        for i in range(400):
            game.run(choices[rng.choice(5, p=[0.6, 0.15, 0.1, 0.1, 0.05])], p2=["RIGHT"] if i % 3 else [])
            if i % 100 == 99:
                snapshots.append(bytes(game.emu.ram))
        enemies = bytes(game.emu.peek(0xFF0060 + i) for i in range(8 * 12))
        return enemies, snapshots
    finally:
        game.close()


def test_same_inputs_give_the_same_ram(dasher_rom: Path) -> None:
    first = _play(dasher_rom, start_frame=10)
    second = _play(dasher_rom, start_frame=10)
    assert first[1] == second[1]
    assert first[0] == second[0]


def test_the_frame_counter_drives_enemy_timing(dasher_rom: Path) -> None:
    # Pressing START one frame later changes where the crawlers are later on.
    early, _ = _play(dasher_rom, start_frame=10)
    late, _ = _play(dasher_rom, start_frame=11)
    assert early != late


def _crawlers_after_sticky_play(game: Dasher, state: bytes, seed: int) -> tuple[list[int], int]:
    game.emu.set_state(state)
    game.emu.forget_action()
    game.emu.set_sticky(0.25, seed)
    for i in range(150):  # 600 frames of hopping on the spot, safe from every hazard
        game.run(["B"] if i % 2 else [], frames=4)
    crawlers = [game.emu.peek(0xFF0060 + 12 * i, ">i2") for i in range(game["enemy_count"])]
    return crawlers, game["rng"]


def test_sticky_actions_change_enemy_timing(playing: Dasher) -> None:
    # The random state mixes in the pads, so a sticky draw (the previous
    # action kept for a frame) changes when crawlers turn, even though the
    # player only hops at the start, far from them.  The same seed replays
    # the same game.
    state = playing.emu.get_state()
    one = _crawlers_after_sticky_play(playing, state, seed=1)
    again = _crawlers_after_sticky_play(playing, state, seed=1)
    other = _crawlers_after_sticky_play(playing, state, seed=2)
    assert one == again
    assert one[1] != other[1]
    assert one[0] != other[0]
    assert playing["p1_deaths"] == 0 and playing["p1_x"] < 100
