"""Our cartridges (tools/cartridges.yaml) driven by their game.yaml field names, for their own test files.

Each cartridge keeps the same conventions (Dasher's first): a title whose main loop counts ``frame``,
``game_mode`` 0 at the title and 1 in play, START to begin, and a RAM map in ``src/ram.h`` whose
``ADDR_*`` and per-player ``P_*`` defines game.yaml repeats.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from pathlib import Path

import yaml

from retrokit.host.emulator import Emulator

MODE_TITLE, MODE_PLAY, MODE_CLEAR, MODE_GAMEOVER = 0, 1, 2, 3  #: game_mode
ALIVE, DYING, OUT, ABSENT = 0, 1, 2, 3  #: pN_state


def game_fields(game_dir: Path) -> dict[str, tuple[int, str]]:
    """game.yaml's fields: name -> (address, type code)."""
    doc = yaml.safe_load((game_dir / "game.yaml").read_text())
    return {name: (int(f["address"]), f["type"]) for name, f in doc["fields"].items()}


def ram_h_fields(ram_h: Path) -> dict[str, int]:
    """A cartridge's src/ram.h addresses by game.yaml's names: ADDR_X -> x, ADDR_Pn + P_X -> pn_x."""
    values = {
        name: int(value, 16)
        for name, value in re.findall(r"^#define (\w+) (0x[0-9A-Fa-f]+)\b", ram_h.read_text(), re.MULTILINE)
    }
    out = {k[len("ADDR_"):].lower(): v for k, v in values.items() if k.startswith("ADDR_")}
    for player in (1, 2):
        if f"ADDR_P{player}" not in values:
            continue  # a one-player cartridge (a Game Boy has one pad)
        for k, v in values.items():
            if k.startswith("P_"):
                out[f"p{player}_{k[2:].lower()}"] = values[f"ADDR_P{player}"] + v
    return out


class CartGame:
    """An emulator running one of our cartridges, with its fields by name (``game["p1_x"]``)."""

    def __init__(self, rom: Path, fields: dict[str, tuple[int, str]], options: dict[str, str] | None = None) -> None:
        self.emu = Emulator.for_rom(rom, options=options)
        self.mask = self.emu.system.mask
        self.fields = fields

    def __getitem__(self, name: str) -> int:
        return self.emu.peek(*self.fields[name])

    def __setitem__(self, name: str, value: int) -> None:
        address, code = self.fields[name]
        self.emu.poke(address, value, code)

    def run(self, p1: Sequence[str] = (), p2: Sequence[str] = (), frames: int = 1) -> None:
        self.emu.run([self.mask(list(p1)), self.mask(list(p2))], frames)

    def run_until(
        self, condition: Callable[[], bool], p1: Sequence[str] = (), p2: Sequence[str] = (), limit: int = 600
    ) -> int:
        """Run frames holding the buttons until ``condition()``; return the frames run."""
        for n in range(limit):
            if condition():
                return n
            self.run(p1, p2)
        raise AssertionError(f"condition not met within {limit} frames")

    def boot(self) -> None:
        """Run until the title's main loop is counting frames.

        From 2, and after the first frame: a core may power on with RAM full of 0xFF, or of a pattern
        (gambatte's work RAM reads ``frame`` 8 before the boot code has run).
        """
        self.run_until(lambda: self.emu.frame > 0 and 2 <= self["frame"] < 100, limit=300)
        assert self["game_mode"] == MODE_TITLE

    def start(self, p1: Sequence[str] = ("START",), p2: Sequence[str] = ()) -> None:
        """Press START for one frame at the title and wait for play to begin."""
        self.run(p1, p2)
        self.run_until(lambda: self["game_mode"] == MODE_PLAY, limit=120)

    def close(self) -> None:
        self.emu.close()


def lose_every_life(game: CartGame, lives: int = 3) -> None:
    """Hold RIGHT into the level's hazards until player 1 is out: each loss counts down, then game over, the title."""
    for left in range(lives - 1, -1, -1):
        game.run_until(lambda: game["p1_state"] == DYING, ["RIGHT"], limit=400)
        assert game["p1_lives"] == left
        game.run_until(lambda: game["p1_state"] != DYING, limit=300)
    assert game["p1_state"] == OUT
    game.run(frames=2)
    assert game["game_mode"] == MODE_GAMEOVER
    game.run_until(lambda: game["game_mode"] == MODE_TITLE, limit=400)


def run_into_goal(game: CartGame) -> None:
    """Run player 1 (put just before ``end_x`` by the caller) into the goal: the clear, its bonus, the next level."""
    game.run_until(lambda: game["level_done"] == 1, ["RIGHT"], limit=120)
    assert game["game_mode"] == MODE_CLEAR
    assert game["p1_score"] >= 1000, "the clear bonus"
    game.run_until(lambda: game["game_mode"] == MODE_PLAY, limit=300)
    assert game["level_done"] == 0
    assert game["p1_x"] == game["start_x"]


def start_selected(game: CartGame, select: dict[str, int], when: str) -> None:
    """Write the level select (``"at-title"`` or ``"before-first-frame"``), press START, check the level began."""
    if when == "at-title":
        game.boot()
        game.run(frames=20)
    for name, value in select.items():
        game[name] = value  # before the first frame: the boot's RAM clear keeps the level select
    if when == "before-first-frame":
        game.boot()
    assert {name: game[name] for name in select} == select
    game.start()
    assert {name: game[name] for name in select} == select
    assert game["level_width"] > game["end_x"]
    assert game["p1_x"] == game["start_x"]
