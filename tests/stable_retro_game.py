"""A stable-retro integration folder for one of our cartridges, and the inputs the system tests play.

stable-retro is the reference the system tests compare against (tests/test_systems.py): for a game of
ours it needs its own integration folder, written here from the game's files: ``data.json`` (the
fields of game.yaml), ``scenario.json`` (below), ``metadata.json`` (the default state), ``rom.sha``,
the ROM and the start state. The folder is registered with stable-retro's custom-path API.

The scenario is Gym Retro's JSON, which both sides load: retrokit converts it (retrokit.dsl.gymretro),
stable-retro runs it in its C++ reader, so equal rewards and dones show the conversion and the fields
agree. Gym Retro's language cannot say what our scenarios say (``peak``, ``initial``), so it is built
from the fields they read: the reward is the change of each unbounded field (a position, a score), and
the episode is done when a bounded field (lives, game mode, a level-done flag) leaves its start value.
"""

from __future__ import annotations

import contextlib
import gzip
import json
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from retrokit.data.games import Game
from retrokit.data.roms import rom_sha1
from retrokit.data.statecheck import load_state, remember_written
from retrokit.data.states import read_state
from retrokit.dsl.scenario import load_scenario
from retrokit.host.emulator import Emulator
from retrokit.host.memory import FieldReader
from retrokit.host.systems import System


@dataclass
class Integration:
    """A stable-retro integration of one of our games.

    Attributes:
        name: stable-retro's name for it, its folder's: ``<Game>-v0`` unless written under another.
        folder: The integration folder (its parent is the custom path).
        scenario: ``scenario.json``, which retrokit loads too.
        state: The start state's name.
        after_reset: Our checked state one frame (no buttons) after the start state: where
            stable-retro's ``reset`` leaves the game, since it runs a frame.
    """

    name: str
    folder: Path
    scenario: Path
    state: str
    after_reset: Path


def _json(path: Path, value: object) -> None:
    path.write_text(json.dumps(value, indent=2))


def _scenario(game: Game, start: dict[str, int]) -> dict:
    """Gym Retro's scenario.json from the fields the game's default scenario reads (module docstring)."""
    read = load_scenario(game.scenario_path(), list(game.fields), game_dir=game.folders[0]).fields
    fields = game.fields
    rewards = {name: {"reward": 1.0, "penalty": 1.0} for name in read if fields[name].range is None}
    dones = {name: {"op": "not-equal", "reference": start[name]} for name in read if fields[name].range is not None}
    return {"reward": {"variables": rewards}, "done": {"variables": dones, "condition": "any"}}


def write_integration(game: Game, root: Path, name: str | None = None) -> Integration:
    """Write a stable-retro integration of ``game`` (its default state) into ``root/<name>``.

    Args:
        name: The folder's name: by default ``<Game>-v0``, as stable-retro's stable games are named; its
            experimental and contrib games' folders have no ``-v0``.
    """
    name = name or f"{game.name}-v0"
    folder = root / name
    folder.mkdir(parents=True)
    rom = game.require_rom()
    (folder / f"rom{rom.suffix}").write_bytes(rom.read_bytes())
    (folder / "rom.sha").write_text(rom_sha1(rom, game.system) + "\n")
    state = game.default_state
    (folder / f"{state}.state").write_bytes(gzip.compress(read_state(game.state_path(state)), mtime=0))
    info = {}
    for field in game.fields.values():
        info[field.name] = {"address": field.address, "type": field.type}
        if field.mask is not None:
            info[field.name]["mask"] = field.mask
    _json(folder / "data.json", {"info": info})
    _json(folder / "metadata.json", {"default_state": state})
    emu = Emulator(game.system, rom)
    try:
        emu.set_state(load_state(game, game.state_path(state)))
        start = FieldReader(list(game.fields.values()), emu.space).read()
        emu.run([0, 0], 1)
        after = root / f"{game.name}.after-reset.state"
        snapshot = emu.get_state()
        after.write_bytes(gzip.compress(bytes(snapshot), mtime=0))
        # Noted as written by retrokit from a core, as retrokit notes each state it saves: loading it back needs no
        # probe in a child (about 1-3 CPU-s; a probe's verdict is kept, but Genesis Plus GX's states hold bytes that
        # differ run to run, and a fresh data folder has none).
        remember_written(game, snapshot, rom)
    finally:
        emu.close()
    _json(folder / "scenario.json", _scenario(game, start))
    return Integration(name, folder, folder / "scenario.json", state, after)


@contextlib.contextmanager
def found_by_both(root: Path) -> Iterator[None]:
    """Game folders under ``root`` found by retrokit (``RETROKIT_GAMES``) and by stable-retro (a custom path)."""
    import stable_retro

    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("RETROKIT_GAMES", str(root))
        stable_retro.data.Integrations.add_custom_path(str(root))
        try:
            yield
        finally:
            stable_retro.data.Integrations.clear_custom_paths()


def wandering(system: System, seed: int, hold: int = 6) -> Iterator[list[str]]:
    """Endless button sets: one combination from each of the system's action groups, each held ``hold`` frames.

    Right is favoured two to one, so the player gets somewhere; console switches never come up, since
    the groups hold none.
    """
    rng = np.random.default_rng(seed)
    groups = [list(group) for group in system.actions]
    while True:
        names: list[str] = []
        for group in groups:
            combo = group[int(rng.integers(0, len(group)))]
            if "LEFT" in combo and rng.random() < 0.5:
                combo = ("RIGHT",)
            names += list(combo)
        for _ in range(hold):
            yield names


def pressed(buttons: list[str | None], names: list[str]) -> np.ndarray:
    """stable-retro's ``all`` action: one 0/1 per RetroPad id."""
    return np.array([b is not None and b in names for b in buttons], dtype=np.int8)
