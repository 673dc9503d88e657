"""Hopper, our NES cartridge, on the real fceumm core through retrokit's host.

The game is documented in tools/nescart/README.md; its RAM map is
games/Hopper-Nes/game.yaml (checked here against tools/nescart/src/ram.h and
the equates of src/crt0.s). The generic checks (byte-for-byte rebuild, every
tool on every system) live in tests/test_cartridges.py and tests/test_systems.py.
"""

from __future__ import annotations

import re
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

from retrokit.data.roms import rom_sha1
from retrokit.host.systems import get_system

REPO = Path(__file__).resolve().parent.parent
GAME_DIR = REPO / "games" / "Hopper-Nes"
CART_DIR = REPO / "tools" / "nescart"
ROM = GAME_DIR / "rom.nes"

# The stages' goal x, from tools/nescart/src/world.c: five columns before each stage's end.
END_X = {(0, 0): 2248, (0, 1): 2312, (1, 0): 2568, (1, 1): 2840, (2, 0): 3192, (2, 1): 3416}
GROUND = 0x0400  # one byte per 16-pixel column: height 0-4 (0 = pit), bit 7 = a coin
ENEMIES, ENEMY_SIZE = 0x0300, 10
FIELDS = game_fields(GAME_DIR)


class Hopper(CartGame):
    """An emulator running Hopper, with the game's fields by name."""

    def __init__(self) -> None:
        super().__init__(ROM, FIELDS)

    def column(self, x: int) -> int:
        return self.emu.peek(GROUND + x // 16)

    def enemy(self, i: int, offset: int, code: str = "|u1") -> int:
        return self.emu.peek(ENEMIES + ENEMY_SIZE * i + offset, code)


@pytest.fixture
def hopper():
    game = Hopper()
    game.boot()
    yield game
    game.close()


@pytest.fixture
def playing(hopper: Hopper) -> Hopper:
    hopper.start()
    return hopper


# --- the ROM and its data file ----------------------------------------------------------------


def test_ines_header_is_nrom_with_vertical_mirroring() -> None:
    rom = ROM.read_bytes()
    assert rom[:4] == b"NES\x1a"
    assert (rom[4], rom[5]) == (2, 1), "32 KiB of PRG, 8 KiB of CHR"
    assert len(rom) == 16 + 2 * 16384 + 8192
    assert rom[6] & 0xF0 == 0 and rom[7] & 0xF0 == 0, "mapper 0"
    assert rom[6] & 1 == 1, "vertical mirroring: the two nametables side by side, for scrolling"
    nmi, reset, irq = (int.from_bytes(rom[16 + 0x7FFA + 2 * i : 16 + 0x7FFC + 2 * i], "little") for i in range(3))
    assert all(0x8000 <= v < 0xFFFA for v in (nmi, reset, irq))


def test_game_yaml_lists_the_committed_rom() -> None:
    doc = yaml.safe_load((GAME_DIR / "game.yaml").read_text())
    assert doc["system"] == "Nes" and doc["players"] == 2
    assert [r["sha1"] for r in doc["roms"]] == [rom_sha1(ROM)]


def test_game_yaml_and_crt0_addresses_match_ram_h() -> None:
    known = ram_h_fields(CART_DIR / "src" / "ram.h")
    for name, (address, _) in FIELDS.items():
        assert name in known, f"game.yaml field {name!r} is not in src/ram.h"
        assert address == known[name], f"{name}: game.yaml says {address:#x}, src/ram.h {known[name]:#x}"
    crt0 = re.findall(r"^(ADDR_\w+)\s*=\s*\$([0-9A-Fa-f]+)", (CART_DIR / "src" / "crt0.s").read_text(), re.MULTILINE)
    assert len(crt0) >= 8
    for name, value in crt0:
        assert int(value, 16) == known[name[len("ADDR_"):].lower()], f"crt0.s {name} disagrees with src/ram.h"
    assert FIELDS["p1_x"][1] == "<u2" and FIELDS["p1_score"][1] == ">n6" and FIELDS["frame"][1] == "<u4"


# --- the console as fceumm shows it -----------------------------------------------------------


def test_frames_are_the_descriptors_cropped_screen(hopper: Hopper) -> None:
    # FCEUmm crops 8 pixels of the PPU's 256x240 on every side: the Nes descriptor's screen.
    assert hopper.emu.screen().shape == (224, 240, 3)
    assert get_system("Nes").screen == (224, 240)


def test_ram_is_2_kib_little_endian(playing: Hopper) -> None:
    ram = playing.emu.ram
    assert len(ram) == 0x800
    address = FIELDS["end_x"][0]
    assert playing["end_x"] > 255
    assert (ram[address], ram[address + 1]) == (playing["end_x"] & 0xFF, playing["end_x"] >> 8)


def test_main_loop_follows_the_nmi(hopper: Hopper) -> None:
    frame, vblanks = hopper["frame"], hopper["vblanks"]
    hopper.run(frames=60)
    assert hopper["frame"] - frame == 60
    assert (hopper["vblanks"] - vblanks) % 0x10000 == 60


def test_play_keeps_pace_with_the_nmi(hopper: Hopper) -> None:
    # cc65's code is slow: the main loop must still finish each frame's work
    # within the frame while both players run with coins and the HUD on screen.
    hopper.start(p1=[], p2=["START"])
    hopper.run_until(lambda: hopper["p1_on_ground"] == 1, limit=120)
    frame, vblanks = hopper["frame"], hopper["vblanks"]
    hopper.run(["RIGHT"], ["RIGHT"], frames=90)
    assert hopper["p1_x"] > 200 and hopper["camera_x"] > 0
    assert hopper["frame"] - frame == hopper["vblanks"] - vblanks == 90


def test_title_shows_and_start_begins(hopper: Hopper) -> None:
    hopper.run(frames=10)
    title = hopper.emu.screen()
    assert len(np.unique(title.reshape(-1, 3), axis=0)) >= 2, "the title's text is on screen"
    hopper.start()
    assert (hopper["world"], hopper["stage"]) == (0, 0)
    assert hopper["p1_state"] == ALIVE and hopper["p1_lives"] == 3
    assert hopper["p2_state"] == ABSENT
    hopper.run(frames=5)
    assert not np.array_equal(hopper.emu.screen(), title)


# --- playing ------------------------------------------------------------------------------------


def test_holding_right_moves_x_and_the_camera(playing: Hopper) -> None:
    x = playing["p1_x"]
    assert x == playing["start_x"]
    playing.run(["RIGHT"], frames=90)
    assert playing["p1_x"] > x + 150
    assert playing["camera_x"] > 0
    right = playing["p1_x"]
    playing.run(["LEFT"], frames=60)  # 20 frames to stop, then back
    assert playing["p1_x"] < right
    assert playing["p1_x"] >= playing["camera_x"] + 8, "the camera never scrolls back"


def test_coins_score_as_one_digit_a_byte(playing: Hopper) -> None:
    # Stage 1-1 opens with three coins at head height (x 192-239).
    playing.run(["RIGHT"], frames=100)
    assert playing["p1_coins"] == 3
    assert playing["p1_score"] == 30, "10 points a coin"
    address = FIELDS["p1_score"][0]
    assert [playing.emu.peek(address + i) for i in range(6)] == [0, 0, 0, 0, 3, 0]


def _first_pit(game: Hopper) -> tuple[int, int]:
    x = game["p1_x"]
    while game.column(x) & 7:
        x += 16
    left = x - x % 16
    right = left
    while not game.column(right) & 7:
        right += 16
    return left, right


@pytest.mark.parametrize("button", ["A", "B"], ids=["jump-A", "jump-B"])
def test_jumping_over_a_pit_keeps_the_life(playing: Hopper, button: str) -> None:
    left, right = _first_pit(playing)
    playing.run_until(lambda: playing["p1_x"] >= left - 24, ["RIGHT"])
    playing.run(["RIGHT", button], frames=20)
    playing.run(["RIGHT"], frames=40)
    assert playing["p1_x"] > right
    assert (playing["p1_state"], playing["p1_lives"], playing["p1_deaths"]) == (ALIVE, 3, 0)


def test_walking_into_a_pit_loses_a_life_and_respawns(playing: Hopper) -> None:
    left, right = _first_pit(playing)
    playing.run_until(lambda: playing["p1_state"] == DYING, ["RIGHT"], limit=400)
    assert left - 8 <= playing["p1_x"] <= right + 8
    assert playing["p1_lives"] == 2
    playing.run_until(lambda: playing["p1_state"] == ALIVE, limit=120)
    assert playing["p1_x"] == playing["start_x"] and playing["camera_x"] == 0
    assert playing["p1_lives"] == 2


def test_losing_every_life_is_game_over(playing: Hopper) -> None:
    lose_every_life(playing)
    assert (playing["world"], playing["stage"]) == (0, 0)


def _near_first_crawler(game: Hopper) -> tuple[int, int]:
    """Put player 1 on the ground 60 pixels left of the first crawler; return its x and feet y."""
    game.run_until(lambda: game["p1_on_ground"] == 1, limit=120)  # a stage begins with a drop from the top
    x, y = game.enemy(0, 0, "<u2"), game.enemy(0, 6)
    game["camera_x"], game["p1_x"] = x - 150, x - 60
    game.run(frames=2)
    assert game["p1_on_ground"] == 1 and game["p1_y"] == y, "stage 1-1's first crawler walks the player's ground"
    return x, y


def test_landing_on_a_crawler_defeats_it(playing: Hopper) -> None:
    _x, y = _near_first_crawler(playing)
    playing["p1_x"], playing["p1_y"] = playing.enemy(0, 0, "<u2"), y - 30  # drop onto it from above
    playing.run_until(lambda: playing.enemy(0, 7) == 0, limit=60)
    assert playing["p1_state"] == ALIVE and playing["p1_vy"] < 0, "the player bounces off"
    assert playing["p1_score"] == 100


def test_walking_into_a_crawler_costs_a_life(playing: Hopper) -> None:
    _near_first_crawler(playing)
    playing.run_until(lambda: playing["p1_state"] == DYING, ["RIGHT"], limit=120)
    assert playing["p1_lives"] == 2
    assert playing.enemy(0, 7) != 0, "the crawler is still there"


def test_reaching_end_x_clears_the_stage(playing: Hopper) -> None:
    playing["camera_x"] = playing["end_x"] - 160
    playing["p1_x"] = playing["end_x"] - 40
    run_into_goal(playing)
    assert (playing["world"], playing["stage"]) == (0, 1)
    assert playing["end_x"] == END_X[0, 1]


def _runner(game: Hopper) -> list[str]:
    """A scripted player 1: hold RIGHT; jump (a fresh press) from the ground when a pit or a wall is
    10-18 pixels ahead or a crawler 16-36 pixels ahead, and hold the jump while rising."""
    x, y = game["p1_x"], game["p1_y"]
    ahead = [game.column(x + d) & 7 for d in (10, 18)]
    danger = any(h == 0 or 224 - 16 * h < y for h in ahead) or any(
        game.enemy(i, 7) and 16 < game.enemy(i, 0, "<u2") - x < 36 for i in range(game["enemy_count"])
    )
    fresh = not game["pad1"] & 0x80
    jump = (game["p1_on_ground"] and danger and fresh) or (not game["p1_on_ground"] and game["p1_jump_held"])
    return ["RIGHT", "A"] if jump else ["RIGHT"]


@pytest.mark.parametrize("world,stage", list(END_X), ids=[f"level{w + 1}-{s + 1}" for w, s in END_X])
def test_every_stage_can_be_cleared(world: int, stage: int) -> None:
    # The level design holds: a simple scripted runner reaches every goal pole within its three lives.
    game = Hopper()
    try:
        start_selected(game, {"world": world, "stage": stage}, "at-title")
        for _ in range(4000):
            if game["level_done"] or game["game_mode"] != 1:
                break
            game.run(_runner(game))
        assert game["level_done"] == 1 and game["p1_x"] >= END_X[world, stage], (game["p1_x"], game["p1_lives"])
    finally:
        game.close()


# --- level select ------------------------------------------------------------------------------


@pytest.mark.parametrize("when", ["at-title", "before-first-frame"])
@pytest.mark.parametrize("world,stage", list(END_X), ids=[f"level{w + 1}-{s + 1}" for w, s in END_X])
def test_writing_world_and_stage_selects_the_level(world: int, stage: int, when: str) -> None:
    game = Hopper()
    try:
        start_selected(game, {"world": world, "stage": stage}, when)
        assert game["end_x"] == END_X[world, stage]
    finally:
        game.close()


# --- two players ---------------------------------------------------------------------------------


def test_start_on_port_2_starts_a_two_player_game(hopper: Hopper) -> None:
    hopper.start(p1=[], p2=["START"])
    assert hopper["p1_state"] == ALIVE and hopper["p2_state"] == ALIVE and hopper["players"] == 2
    assert hopper["p2_x"] == hopper["start_x"] - 16
    hopper.run_until(lambda: hopper["p2_on_ground"] == 1, limit=120)
    x1, x2 = hopper["p1_x"], hopper["p2_x"]
    hopper.run(p2=["RIGHT"], frames=40)
    assert hopper["p2_x"] > x2 + 40 and hopper["p1_x"] == x1, "port 2 moves player 2 only"
    hopper.run(p2=["B"], frames=4)
    assert hopper["p2_vy"] < 0, "player 2 jumps"
    hopper.run(["RIGHT"], frames=20)
    assert hopper["p1_x"] > x1


def test_any_button_on_port_2_joins_player_2(playing: Hopper) -> None:
    playing.run(["RIGHT"], frames=30)
    assert playing["p2_state"] == ABSENT
    playing.run(p2=["A"])
    assert playing["p2_state"] == ALIVE and playing["p2_lives"] == 3
    assert playing["p2_x"] == playing["p1_x"], "player 2 joins beside the leader"


# --- determinism and randomness ------------------------------------------------------------------


def _play(start_frame: int, seed: int = 7) -> tuple[bytes, bytes]:
    """Start on a given frame, play fixed pseudo-random inputs; return the crawlers and the RAM."""
    game = Hopper()
    try:
        game.boot()
        game.run(frames=start_frame)
        game.start()
        rng = np.random.default_rng(seed)
        choices = [["RIGHT"], ["RIGHT", "A"], ["RIGHT", "B"], [], ["LEFT"]]
        for _ in range(300):
            game.run(choices[rng.choice(5, p=[0.6, 0.15, 0.1, 0.1, 0.05])])
        crawlers = bytes(game.emu.peek(ENEMIES + i) for i in range(8 * ENEMY_SIZE))
        return crawlers, bytes(game.emu.ram)
    finally:
        game.close()


def test_same_inputs_give_the_same_ram_and_the_start_frame_changes_the_crawlers() -> None:
    first, again, late = _play(10), _play(10), _play(11)
    assert first == again
    assert first[0] != late[0], "pressing START a frame later changes when crawlers turn"
