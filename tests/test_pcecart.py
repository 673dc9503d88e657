"""Skipper, our PC Engine cartridge, on the real mednafen_pce_fast core through retrokit's host.

The game is documented in tools/pcecart/README.md; its RAM map is
games/Skipper-PCEngine/game.yaml (checked here against tools/pcecart/src/ram.h).
The byte-for-byte rebuild is tests/test_cartridges.py's; every tool on this
system is tests/test_systems.py's. Here: the game itself, and the facts about
the core that the PCEngine descriptor rests on.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest
import yaml
from cartgame import CartGame, game_fields, ram_h_fields

import retrokit

REPO = Path(__file__).resolve().parent.parent
GAME_DIR = REPO / "games" / "Skipper-PCEngine"
ROM = GAME_DIR / "rom.pce"
CART_DIR = REPO / "tools" / "pcecart"
RAM_BASE = 0xF80000  # console address of work RAM's first byte, logical $2000
GROUND = 0xF80300  # ground height in tiles per 8-pixel column, 0 = pit
CRAWLERS = 0xF80200  # 6 x 10 bytes: <u2 x, <u2 x0, <u2 x1, |u1 y, |u1 state (0 gone), |i1 direction, |u1 pause
END_X = {0: 1200, 1: 1520, 2: 1840}  # tools/pcecart/src/levels.c
TITLE, PLAY, CLEAR, GAMEOVER = 0, 1, 2, 3
ALIVE, DYING = 0, 1


FIELDS = game_fields(GAME_DIR)


class Skipper(CartGame):
    """An emulator running Skipper, with the game's fields by name."""

    def __init__(self, options: dict[str, str] | None = None) -> None:
        super().__init__(ROM, FIELDS, options)

    def start(self, level: int | None = None) -> None:
        """Select a level by poking it at the title, press RUN, and wait for play."""
        if level is not None:
            self["level"] = level
        super().start(["RUN"])

    def ground(self, x: int) -> int:
        return self.emu.peek(GROUND + x // 8)

    def first_pit(self) -> tuple[int, int]:
        """The first pit right of the player: its left and right edges, level pixels."""
        x = self["x"]
        while self.ground(x):
            x += 8
        left = x - x % 8
        right = left
        while not self.ground(right):
            right += 8
        return left, right

    def pad(self, buttons: Sequence[str], frames: int = 1) -> list[int]:
        """The pad byte the game reads on each of ``frames`` frames holding the buttons."""
        seen = []
        for _ in range(frames):
            self.run(buttons)
            seen.append(self["pad"])
        return seen


@pytest.fixture
def skipper():
    game = Skipper()
    game.boot()
    yield game
    game.close()


@pytest.fixture
def playing(skipper: Skipper) -> Skipper:
    skipper.start()
    return skipper


# --- the ROM and its data file ----------------------------------------------------------------


def test_rom_boots_from_bank_0() -> None:
    rom = ROM.read_bytes()
    assert len(rom) == 32 * 1024
    # At power-on the console maps ROM bank 0 at $E000: the reset vector is at the end of the file's first 8 KiB.
    reset = int.from_bytes(rom[0x1FFE:0x2000], "little")
    assert 0xE000 <= reset < 0xFFF6


def test_game_yaml_lists_the_committed_rom() -> None:
    doc = yaml.safe_load((GAME_DIR / "game.yaml").read_text())
    assert [r["sha1"] for r in doc["roms"]] == [hashlib.sha1(ROM.read_bytes()).hexdigest()]
    assert doc["players"] == 1 and doc["system"] == "PCEngine"


def _ram_h() -> dict[str, int]:
    """src/ram.h's fixed addresses (logical, from $2000), as console addresses by game.yaml's field names."""
    return {name: RAM_BASE + logical - 0x2000 for name, logical in ram_h_fields(CART_DIR / "src" / "ram.h").items()}


def test_game_yaml_addresses_match_the_source() -> None:
    known = _ram_h()
    for name, (address, _) in FIELDS.items():
        assert name in known, f"game.yaml field {name!r} is not in src/ram.h"
        assert address == known[name], f"{name}: game.yaml says {address:#x}, src/ram.h {known[name]:#x}"
    assert (GROUND, CRAWLERS) == (known["ground"], known["enemies"])
    assert FIELDS["x"][1] == "<u2" and FIELDS["y"][1] == "<i2" and FIELDS["score"][1] == ">d4"


# --- the core, as the PCEngine descriptor describes it -----------------------------------------


def test_work_ram_is_logical_2000_at_console_f80000(skipper: Skipper) -> None:
    ram = skipper.emu.ram
    # The wheel's core reports the SuperGrafx's 32 KiB; a PC Engine uses the first 8 KiB, the rest stays 0xFF.
    assert len(ram) == 32 * 1024
    assert (ram[0x2000:] == 0xFF).all()
    frame = skipper["frame"]
    assert frame > 0
    assert int(ram[0x48]) | int(ram[0x49]) << 8 == frame, "logical $2048 (frame, little-endian) is buffer offset 0x48"


def test_screen_is_242_lines_of_256_pixels() -> None:
    env = retrokit.make("Skipper-PCEngine", state="Level1")
    try:
        obs, _ = env.reset(seed=0)
        for _ in range(10):
            obs, *_ = env.step(env.action_space.sample() * 0)
        assert obs.shape == (242, 256, 3)
        assert len(np.unique(obs.reshape(-1, 3), axis=0)) > 4, "a blank screen"
        assert env.metadata["render_fps"] == pytest.approx(59.826)
    finally:
        env.close()


def test_each_pad_button_reaches_the_game(skipper: Skipper) -> None:
    bits = {"I": 1, "II": 2, "SELECT": 4, "UP": 16, "RIGHT": 32, "DOWN": 64, "LEFT": 128}
    for name, bit in bits.items():
        assert skipper.pad([name], 2)[-1] == bit, name
        skipper.run()
    assert skipper.pad(["I", "II"], 2)[-1] == 3
    skipper.run()
    # V and VI (RetroPad L and R) are buttons of a 6-button pad, which the core's pad is not.
    assert skipper.pad(["V", "VI"], 4) == [0, 0, 0, 0]


@pytest.mark.parametrize(("switch", "fires"), [("III", "II"), ("IV", "I")])
def test_iii_and_iv_toggle_turbo_so_no_action_group_has_them(skipper: Skipper, switch: str, fires: str) -> None:
    """III and IV toggle turbo on II and I. The descriptor leaves the turbo delay unanswered, as stable-retro
    does, so the core's delay stays 0 and a turbo button fires on every frame: the toggle changes nothing. With
    a delay set (the core option pce_Turbo_Delay) it fires on and off, a setting no save state holds."""
    bit = {"I": 1, "II": 2}[fires]
    skipper.run()
    skipper.pad([switch], 2)
    skipper.run()
    assert skipper.pad([fires], 8) == [bit] * 8, "with the delay unanswered, turbo is held on every frame"
    skipper.pad([switch], 2)  # toggled back, for the tests that follow
    fast = Skipper({"pce_Turbo_Delay": "Fast"})
    try:
        fast.boot()
        state = fast.emu.get_state()
        assert fast.pad([fires], 8) == [bit] * 8
        fast.run()
        fast.pad([switch], 2)
        fast.run()
        turbo = fast.pad([fires], 8)
        assert 0 in turbo and bit in turbo, f"holding {fires} after pressing {switch} fires on and off: {turbo}"
        fast.emu.set_state(state)
        fast.run()
        assert 0 in fast.pad([fires], 8), "the turbo outlives a state load"
    finally:
        fast.close()
    system = skipper.emu.system
    assert set(system.switches) == {"III", "IV"}, "the descriptor calls them switches: agents leave them alone"
    groups = system.actions
    assert not any(b in combo for group in groups for combo in group for b in ("III", "IV", "V", "VI"))
    assert ("I",) in groups[2] and ("II",) in groups[2]


# --- playing ------------------------------------------------------------------------------------


def test_starts_on_run_at_the_title(skipper: Skipper) -> None:
    skipper.run(frames=30)
    assert skipper["game_mode"] == TITLE, "the title waits for RUN"
    skipper.start()
    assert (skipper["level"], skipper["lives"], skipper["score"], skipper["state"]) == (0, 3, 0, ALIVE)
    assert skipper["x"] == skipper["start_x"] and skipper["y"] == 208


def test_main_loop_keeps_up_with_vblank(playing: Skipper) -> None:
    frame, vblanks, lag = playing["frame"], playing["vblanks"], playing["lag"]
    playing.run(["RIGHT"], frames=120)
    assert playing["frame"] - frame == 120
    assert (playing["vblanks"] - vblanks) % 256 == 120
    assert playing["lag"] == lag, "a frame of play took longer than a frame"


def test_holding_right_moves_x_and_the_camera(playing: Skipper) -> None:
    x = playing["x"]
    playing.run(["RIGHT"], frames=50)
    assert playing["x"] > x + 80
    assert playing["camera_x"] > 0, "the camera scrolls with the player"
    right = playing["x"]
    playing.run(["LEFT"], frames=60)  # it slides to a stop first
    assert playing["x"] < right
    playing.run(frames=30)
    assert playing["vx"] == 0
    both = playing["x"]
    playing.run(["LEFT", "RIGHT"], frames=30)
    assert playing["x"] == both, "left and right at once steer neither way"


def test_coins_score_in_bcd(playing: Skipper) -> None:
    # Level 1 opens with four coins at head height (columns 12-15, x 96-127).
    playing.run_until(lambda: playing["x"] >= 136, ["RIGHT"], limit=120)
    assert playing["coins"] == 4
    assert playing["score"] == 40
    assert playing.emu.peek(FIELDS["score"][0] + 3) == 0x40, "8 BCD digits, most significant byte first"


@pytest.mark.parametrize("button", ["I", "II"], ids=["jump-I", "jump-II"])
def test_jumping_over_a_pit_keeps_the_life(playing: Skipper, button: str) -> None:
    left, right = playing.first_pit()
    playing.run_until(lambda: playing["x"] >= left - 30, ["RIGHT"])
    playing.run(["RIGHT", button], frames=20)
    playing.run_until(lambda: playing["on_ground"] == 1, ["RIGHT"])
    assert playing["x"] > right
    assert (playing["state"], playing["lives"], playing["deaths"]) == (ALIVE, 3, 0)


def test_walking_into_a_pit_loses_a_life_and_respawns(playing: Skipper) -> None:
    left, right = playing.first_pit()
    playing.run_until(lambda: playing["state"] == DYING, ["RIGHT"], limit=300)
    assert left - 8 <= playing["x"] <= right
    assert playing["lives"] == 2 and playing["deaths"] == 1
    playing.run_until(lambda: playing["state"] == ALIVE, limit=300)
    assert playing["x"] == playing["start_x"] and playing["camera_x"] == 0
    assert playing["lives"] == 2


def _crawler_ahead(game: Skipper) -> int:
    """The address of the first live crawler right of the player."""
    live = []
    for i in range(game["enemy_count"]):
        at = CRAWLERS + 10 * i
        if game.emu.peek(at + 7) and game.emu.peek(at, "<u2") > game["x"]:
            live.append((game.emu.peek(at, "<u2"), at))
    return min(live)[1]


def test_a_crawler_on_the_ground_costs_a_life(playing: Skipper) -> None:
    crawler = _crawler_ahead(playing)
    # Stand in its patrol, clear of pits: it walks into the player.
    playing["x"] = playing.emu.peek(crawler + 2, "<u2") + 4
    playing.run_until(lambda: playing["state"] == DYING, limit=600)
    assert playing["lives"] == 2
    assert playing.emu.peek(crawler + 7) != 0, "the crawler lives on"


def test_a_player_in_the_air_defeats_a_crawler(playing: Skipper) -> None:
    crawler = _crawler_ahead(playing)
    score = playing["score"]
    # Drop the player onto it from above.
    playing["x"] = playing.emu.peek(crawler, "<u2")
    playing["y"] = playing.emu.peek(crawler + 6) - 30
    playing["on_ground"] = 0
    playing.run_until(lambda: playing.emu.peek(crawler + 7) == 0 or playing["state"] != ALIVE, limit=120)
    assert playing["state"] == ALIVE and playing.emu.peek(crawler + 7) == 0
    assert playing["vy"] < 0, "it bounces off the crawler"
    assert playing["score"] - score == 100


def test_losing_every_life_is_game_over(playing: Skipper) -> None:
    for lives in (2, 1, 0):
        playing.run_until(lambda: playing["state"] == DYING, ["RIGHT"], limit=400)
        assert playing["lives"] == lives
        playing.run_until(lambda: playing["state"] == ALIVE or playing["game_mode"] == GAMEOVER, limit=300)
    assert playing["game_mode"] == GAMEOVER
    playing.run_until(lambda: playing["game_mode"] == TITLE, limit=400)
    playing.start()
    assert (playing["lives"], playing["deaths"], playing["score"]) == (3, 0, 0)


def test_reaching_end_x_clears_the_level(playing: Skipper) -> None:
    end_x = playing["end_x"]
    assert end_x == END_X[0] and playing.ground(end_x - 48) and playing.ground(end_x)
    playing["x"] = end_x - 48  # flat ground before the goal
    playing.run_until(lambda: playing["level_done"] == 1, ["RIGHT"], limit=120)
    assert playing["x"] >= end_x
    assert (playing["game_mode"], playing["score"]) == (CLEAR, 1000)
    playing.run_until(lambda: playing["game_mode"] == PLAY, limit=400)
    assert (playing["level"], playing["level_done"], playing["end_x"]) == (1, 0, END_X[1])
    assert playing["score"] == 1000 and playing["lives"] == 3


@pytest.mark.parametrize(("poked", "level"), [(0, 0), (1, 1), (2, 2), (3, 0), (200, 0)],
                         ids=["level-1", "level-2", "level-3", "out-of-range-3", "out-of-range-200"])  # fmt: skip
def test_level_select_by_poke(skipper: Skipper, poked: int, level: int) -> None:
    skipper.start(poked)
    assert skipper["level"] == level
    assert skipper["end_x"] == END_X[level]
    assert skipper["level_width"] == {0: 1280, 1: 1600, 2: 1920}[level]


def test_same_inputs_from_a_state_replay_the_same_game(playing: Skipper) -> None:
    state = playing.emu.get_state()
    rng = np.random.default_rng(7)
    inputs = [
        list(rng.choice(["RIGHT", "LEFT", "I", "II"], size=rng.integers(0, 3), replace=False)) for _ in range(300)
    ]
    runs = []
    for _ in range(2):
        playing.emu.set_state(state)
        trace = []
        for buttons in inputs:
            playing.run(buttons)
            trace.append((playing["x"], playing["y"], playing["rng"], playing["score"]))
        runs.append((trace, bytes(playing.emu.ram[:0x2000])))
    assert runs[0] == runs[1]
    assert len({t[2] for t in runs[0][0]}) > 200, "the random state moves every frame"


@pytest.mark.parametrize("level", [0, 1, 2], ids=["level-1", "level-2", "level-3"])
def test_a_live_player_never_sinks_into_the_ground(skipper: Skipper, level: int) -> None:
    # Random running and jumping; a wall beside the player once let it fall through the ground next to it.
    skipper.start(level)
    rng = np.random.default_rng(level)
    step = 8  # src/player.c's STEP: a foot may be this far below a column's top for a frame, walking up
    for _ in range(500):
        buttons = ["RIGHT"] if rng.random() < 0.8 else ["LEFT"]
        if rng.random() < 0.3:
            buttons.append("I")
        skipper.run(buttons, frames=int(rng.integers(1, 8)))
        if skipper["game_mode"] != PLAY or skipper["state"] != ALIVE:
            skipper.run_until(lambda: skipper["game_mode"] == TITLE or (skipper["game_mode"], skipper["state"]) == (PLAY, ALIVE),
                             limit=600)  # fmt: skip
            if skipper["game_mode"] == TITLE:  # after a game over
                skipper.start(level)
            continue
        x, y = skipper["x"], skipper["y"]
        for foot in (x - 5, x + 5):
            height = skipper.ground(foot)
            assert not height or y <= 240 - 8 * height + step, f"feet at y {y} inside the ground at x {foot}"


def _hazard_ahead(game: Skipper) -> bool:
    """A pit, a wall or a live crawler just ahead of the player."""
    x, y = game["x"], game["y"]
    for d in range(6, 22, 2):
        height = game.ground(x + d)
        if not height or 240 - 8 * height < y - 8:
            return True
    for i in range(game["enemy_count"]):
        at = CRAWLERS + 10 * i
        if game.emu.peek(at + 7) and 0 < game.emu.peek(at, "<u2") - x < 36:
            return True
    return False


@pytest.mark.parametrize("level", [0, 1, 2], ids=["level-1", "level-2", "level-3"])
def test_every_level_can_be_cleared(skipper: Skipper, level: int) -> None:
    # A simple runner: hold RIGHT, and jump (held 20 frames) when a pit, a wall or a crawler is just ahead.
    skipper.start(level)
    hold = 0
    for _ in range(3000):
        if skipper["game_mode"] != PLAY:
            break
        if skipper["on_ground"] and not skipper["pad"] & 1 and _hazard_ahead(skipper):
            hold = 20
        skipper.run(["RIGHT", "I"] if hold else ["RIGHT"])
        hold = max(hold - 1, 0)
    assert skipper["level_done"] == 1 and skipper["x"] >= END_X[level]
    assert skipper["lives"] > 0
