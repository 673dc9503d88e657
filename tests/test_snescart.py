"""Skipper, our SNES cartridge, on the real snes9x core through retrokit's host.

The game is documented in tools/snescart/README.md and its RAM map is tools/snescart/src/ram.inc,
which games/Skipper-Snes/game.yaml repeats. The byte-for-byte rebuild is tests/test_cartridges.py's,
and every retrokit tool on the ROM is tests/test_systems.py's: this file tests the game itself, its
LoROM header, and the facts of snes9x that the Snes descriptor in host/systems.yaml relies on.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from cartgame import ABSENT, ALIVE, DYING, OUT, CartGame, game_fields, lose_every_life, run_into_goal, start_selected

from retrokit.data.roms import guess_system
from retrokit.host.systems import get_system

REPO = Path(__file__).resolve().parent.parent
GAME_DIR = REPO / "games" / "Skipper-Snes"
ROM = GAME_DIR / "rom.sfc"
RAM_INC = REPO / "tools" / "snescart" / "src" / "ram.inc"
FIELDS = game_fields(GAME_DIR)
WRAM = 0x7E0000
# Level 1's first pit, columns 44-46: past where 240 frames of test_systems' wandering inputs reach.
FIRST_PIT = (352, 376)
JUMP_BUTTONS = ["B", "Y", "A", "X"]


@pytest.fixture
def game() -> Iterator[CartGame]:
    g = CartGame(ROM, FIELDS)
    yield g
    g.close()


@pytest.fixture
def playing(game: CartGame) -> CartGame:
    game.boot()
    game.start()
    return game


def test_lorom_header_checksum_and_vectors() -> None:
    rom = ROM.read_bytes()
    assert len(rom) == 0x8000
    header = rom[0x7FC0:0x7FE0]
    assert header[:21] == b"SKIPPER".ljust(21)
    assert header[0x15] == 0x20, "LoROM"
    assert header[0x17] == 5, "2**5 KiB"
    complement, checksum = int.from_bytes(header[0x1C:0x1E], "little"), int.from_bytes(header[0x1E:0x20], "little")
    assert complement ^ checksum == 0xFFFF
    assert sum(rom) & 0xFFFF == checksum
    reset = int.from_bytes(rom[0x7FFC:0x7FFE], "little")
    assert 0x8000 <= reset < 0xFFC0
    system, how = guess_system(rom, "skipper.bin")  # the Snes descriptor's detect rule, not the extension
    assert (system.name if system else None, how) == ("Snes", "header")


def test_game_yaml_addresses_match_ram_inc() -> None:
    text = RAM_INC.read_text()
    values = {k: int(v, 16) for k, v in re.findall(r"^(\w+)\s*=\s*\$([0-9A-Fa-f]+)", text, re.MULTILINE)}
    expected = {k[len("ADDR_") :].lower(): WRAM + v for k, v in values.items() if k.startswith("ADDR_")}
    for player in (1, 2):
        base = values[f"ADDR_P{player}"]
        expected.update(
            {f"p{player}_{k[2:].lower()}": WRAM + base + v for k, v in values.items() if k.startswith("P_")}
        )
    for name, (address, _) in FIELDS.items():
        assert expected.get(name) == address, name
    assert {"p1_x", "p1_score", "p1_lives", "level", "level_done"} <= FIELDS.keys()


def test_core_reports_256x224_and_128_kib_of_little_endian_ram(playing: CartGame) -> None:
    emu = playing.emu
    assert emu.screen().shape == (224, 256, 3)
    assert get_system("Snes").ram_base == WRAM
    assert len(emu.ram) == 0x20000
    playing["p1_x"] = 0x1234
    assert emu.ram[0x40] == 0x34 and emu.ram[0x41] == 0x12
    assert emu.peek(0x0040, "<u2") == 0x1234, "snes9x maps bank 0's $0000-$1FFF onto the same RAM"


def test_title_shows_level_select_and_start_begins(game: CartGame) -> None:
    game.boot()
    assert game["game_mode"] == 0
    frame = game.emu.screen()
    assert len(np.unique(frame.reshape(-1, 3), axis=0)) >= 2, "the title's text"
    game.start()
    assert game["level"] == 0 and game["p1_x"] == game["start_x"] == 40
    assert game["p1_lives"] == 3 and game["p1_state"] == ALIVE and game["p2_state"] == ABSENT


def test_main_loop_runs_once_a_frame(playing: CartGame) -> None:
    before = playing["frame"], playing["vblanks"]
    playing.run(["RIGHT"], frames=120)
    assert playing["frame"] - before[0] == 120
    assert playing["vblanks"] - before[1] == 120


def test_holding_right_moves_scrolls_and_scores_in_bcd(playing: CartGame) -> None:
    playing.run(["RIGHT"], frames=60)
    assert playing["p1_x"] == 40 + 2 * 60
    assert playing["camera_x"] == 160 - 112
    assert playing["p1_score"] == 10 * (160 // 16 - 40 // 16)
    playing["p1_score"] = 1990  # BCD carries: 0x00001990 + 0x10
    playing.run(["RIGHT"], frames=8)
    assert playing.emu.peek(FIELDS["p1_score"][0], "<u4") == 0x2000


@pytest.mark.parametrize("button", JUMP_BUTTONS)
def test_every_face_button_jumps_over_the_pit(playing: CartGame, button: str) -> None:
    playing.run_until(lambda: playing["p1_x"] >= FIRST_PIT[0] - 24, ["RIGHT"])
    playing.run(["RIGHT", button])
    assert playing["p1_on_ground"] == 0 and playing["p1_vy"] < 0
    playing.run_until(lambda: playing["p1_on_ground"] == 1, ["RIGHT"], limit=60)
    assert playing["p1_x"] >= FIRST_PIT[1] and playing["p1_y"] == 192
    assert playing["p1_lives"] == 3


def test_walking_into_a_pit_loses_a_life_and_respawns(playing: CartGame) -> None:
    playing.run_until(lambda: playing["p1_state"] == DYING, ["RIGHT"], limit=300)
    assert FIRST_PIT[0] <= playing["p1_x"] < FIRST_PIT[1]
    assert playing["p1_lives"] == 2 and playing["p1_deaths"] == 1
    playing.run_until(lambda: playing["p1_state"] == ALIVE, limit=120)
    assert playing["p1_on_ground"] == 1 and playing["p1_y"] == 192


def test_losing_every_life_is_game_over(playing: CartGame) -> None:
    lose_every_life(playing)
    assert playing["level"] == 0


def test_reaching_end_x_clears_the_level(playing: CartGame) -> None:
    playing["p1_x"] = playing["end_x"] - 40
    playing.run(frames=2)  # the camera catches up
    run_into_goal(playing)
    assert playing["level"] == 1 and playing["p1_score"] >= 1000


def test_clearing_the_last_level_returns_to_the_title(game: CartGame) -> None:
    game.boot()
    game["level"] = 2
    game.start()
    game["p1_x"] = game["end_x"] - 40
    game.run(frames=2)
    game.run_until(lambda: game["level_done"] == 1, ["RIGHT"], limit=120)
    game.run_until(lambda: game["game_mode"] == 0, limit=300)
    assert game["level"] == 0


@pytest.mark.parametrize("level", [0, 1, 2])
@pytest.mark.parametrize("when", ["at-title", "before-first-frame"])
def test_writing_level_selects_it(game: CartGame, level: int, when: str) -> None:
    start_selected(game, {"level": level}, when)
    assert game["end_x"] == (1200, 1440, 1700)[level]


def test_start_on_port_2_starts_a_two_player_game(game: CartGame) -> None:
    game.boot()
    game.start(p1=(), p2=("START",))
    assert game["p2_state"] == ALIVE and game["p2_x"] == game["start_x"] - 16
    game.run([], ["RIGHT"], frames=30)
    assert game["p2_x"] == game["start_x"] - 16 + 60 and game["p1_x"] == game["start_x"]
    game.run([], ["RIGHT", "Y"])
    assert game["p2_on_ground"] == 0 and game["p1_on_ground"] == 1


def test_any_button_on_port_2_joins_player_2(playing: CartGame) -> None:
    playing.run(["RIGHT"], frames=10)
    assert playing["p2_state"] == ABSENT
    playing.run(["RIGHT"], ["L"])
    assert playing["p2_state"] == ALIVE and playing["p2_lives"] == 3
    assert playing["p2_x"] >= playing["camera_x"] + 24


def test_game_goes_on_while_one_player_is_left(game: CartGame) -> None:
    game.boot()
    game.start(p1=(), p2=("START",))
    game["p1_lives"] = 1
    game.run_until(lambda: game["p1_state"] == OUT, ["RIGHT"], limit=300)
    assert game["game_mode"] == 1, "player 2 still plays"
    game.run([], ["RIGHT"], frames=10)
    assert game["camera_x"] > 0


def test_same_inputs_give_the_same_ram_and_screen(playing: CartGame) -> None:
    state = playing.emu.get_state()
    rng = np.random.default_rng(7)
    inputs = [[b for b in ("RIGHT", "B", "LEFT") if rng.random() < 0.5] for _ in range(300)]
    runs = []
    for _ in range(2):
        playing.emu.set_state(state)
        for buttons in inputs:
            playing.run(buttons)
        runs.append((bytes(playing.emu.ram), playing.emu.screen().tobytes()))
    assert runs[0] == runs[1]
    assert playing["rng"] != 0


@pytest.mark.parametrize("level", [0, 1, 2], ids=["level1", "level2", "level3"])
def test_a_scripted_runner_clears_every_level_with_two_players(game: CartGame, level: int) -> None:
    """Hold RIGHT and jump (a fresh press) where the ground map shows a pit or a wall ahead: the level design holds."""
    game.boot()
    game["level"] = level
    game.start(p1=(), p2=("START",))
    held = {1: False, 2: False}

    def ground(x: int) -> int:
        return game.emu.peek(WRAM + 0x200 + min(255, x // 8))

    def buttons(p: int) -> list[str]:
        x = game[f"p{p}_x"]
        ahead = [ground(x + d) for d in (4, 8, 12)]
        want = game[f"p{p}_on_ground"] == 1 and any(h == 0 or h > ground(x) for h in ahead)
        press = want and not held[p]
        held[p] = press
        return ["RIGHT", "B"] if press else ["RIGHT"]

    for _ in range(1500):
        if game["game_mode"] != 1:
            break
        game.run(buttons(1), buttons(2))
    assert game["level_done"] == 1
    assert game["p1_lives"] == 3 and game["p2_lives"] == 3
    assert game["p1_score"] >= 1000 and game["p2_score"] > 0
