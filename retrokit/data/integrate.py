"""Making and checking save states from recipes in a game's data file.

A recipe says how to reach a state from power-on: which fields to write (a
level select), which buttons to press, and the field values that mark
arrival. ``retrokit integrate GAME`` makes every state a game's ``game.yaml``
has a recipe for, and checks the ones already there::

    integrate:
      Zone1.Act1:
        set: {zone: 0, act: 0}         # written every frame until arrival
        press: [START]                 # port 1; or {1: [START], 2: [START]}
        until: {game_mode: 1}          # every field equal: arrived
        settle: 0                      # frames to run after arrival

A made state is compared with a state file by the RAM and screen they lead
to, never by their bytes: Genesis Plus GX's states hold host pointers that
differ from one process to the next.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from retrokit.data.games import Game
from retrokit.data.states import read_state, write_state
from retrokit.errors import DataFileError, InvalidArgumentError, StateError, StateNotFoundError, did_you_mean
from retrokit.host.emulator import Emulator
from retrokit.host.memory import FieldReader

HOLD_FRAMES = 2  # a press is held this long, then released as long, until arrival
CHECK_FRAMES = 60  # frames run from a state to compare two states


@dataclass(frozen=True)
class Recipe:
    """How to reach one state from power-on."""

    name: str
    set: Mapping[str, int] = field(default_factory=dict)
    press: Mapping[int, tuple[str, ...]] = field(default_factory=dict)
    until: Mapping[str, int] = field(default_factory=dict)
    settle: int = 0
    max_frames: int = 3000


def recipes(game: Game) -> dict[str, Recipe]:
    """Return the game's state recipes, checked against its fields and buttons.

    Raises:
        DataFileError: A recipe is malformed or names an unknown field.
    """
    raw = game.info.extra.get("integrate") or {}
    if not isinstance(raw, Mapping):
        raise DataFileError(
            f"{game.info.source}: expected 'integrate' to map state names to recipes, got {type(raw).__name__}."
        )
    return {str(name): _recipe(game, str(name), spec) for name, spec in raw.items()}


def _recipe(game: Game, name: str, spec: Any) -> Recipe:
    where = f"{game.info.source}: the recipe of state {name!r}"
    if not isinstance(spec, Mapping):
        raise DataFileError(f"{where}: expected a mapping with set, press, until, got {spec!r}.")
    unknown = set(spec) - {"set", "press", "until", "settle", "max_frames"}
    if unknown:
        key = min(unknown)
        raise DataFileError(
            f"{where}: expected only the keys set, press, until, settle, max_frames; got {key!r}."
            + did_you_mean(key, ["set", "press", "until", "settle", "max_frames"])
        )
    for part in ("set", "until"):
        for key in spec.get(part) or {}:
            if key not in game.fields:
                raise DataFileError(f"{where}: {part} names no field of the game: {key!r}." + did_you_mean(key, game.fields))
    if not spec.get("until"):
        raise DataFileError(f"{where}: expected 'until', the field values that mark arrival, such as {{game_mode: 1}}.")
    press = spec.get("press") or {}
    if not isinstance(press, Mapping):
        press = {1: press}
    return Recipe(
        name=name,
        set={str(k): int(v) for k, v in (spec.get("set") or {}).items()},
        press={int(port): tuple(buttons) for port, buttons in press.items()},
        until={str(k): int(v) for k, v in spec["until"].items()},
        settle=int(spec.get("settle", 0)),
        max_frames=int(spec.get("max_frames", 3000)),
    )


def make_state(game: Game, recipe: Recipe) -> bytes:
    """Play a recipe from power-on and return the state it reaches.

    Raises:
        StateError: The recipe did not arrive within its frame budget.
    """
    with Emulator(game.system, game.require_rom()) as emu:
        reader = FieldReader(game.fields, emu.space)
        masks = [0] * emu.ports
        for port, buttons in recipe.press.items():
            if not 1 <= port <= emu.ports:
                raise InvalidArgumentError(f"Expected ports 1 to {emu.ports} in the recipe of {recipe.name!r}, got {port}.")
            masks[port - 1] = emu.system.mask(buttons)
        for frame in range(recipe.max_frames):
            for name, value in recipe.set.items():
                reader.write(name, value)
            values = reader.read()
            if all(values[k] == v for k, v in recipe.until.items()):
                emu.run([0] * emu.ports, recipe.settle)
                return emu.get_state()
            pressed = (frame // HOLD_FRAMES) % 2 == 0
            emu.run(masks if pressed else [0] * emu.ports, 1)
        seen = {k: values[k] for k in recipe.until}
        raise StateError(
            f"Expected the recipe of {game.name} state {recipe.name!r} to reach {dict(recipe.until)} within "
            f"{recipe.max_frames} frames; it ended at {seen}. Check its set, press and until in game.yaml."
        )


def fingerprint(game: Game, state: bytes) -> str:
    """A digest of where a state leads: RAM and screen after some idle frames."""
    with Emulator(game.system, game.require_rom()) as emu:
        emu.set_state(state)
        emu.run([0] * emu.ports, CHECK_FRAMES)
        return hashlib.sha1(np.asarray(emu.ram).tobytes() + emu.screen().tobytes()).hexdigest()


@dataclass
class Outcome:
    """What integrating one state did."""

    name: str
    status: str  # "made", "up to date", "replaced", "differs"
    path: Path


def integrate(game: Game, names: list[str] | None = None, *, force: bool = False) -> list[Outcome]:
    """Make the game's states from their recipes, and check those already made.

    Args:
        game: The game.
        names: The states to integrate; all with a recipe when ``None``.
        force: Replace a state file that leads somewhere else than its recipe.

    Returns:
        One outcome per state. ``"differs"`` means the file was kept although
        it does not match its recipe (rerun with ``force`` to replace it).
    """
    known = recipes(game)
    if not known:
        raise StateNotFoundError(
            f"Expected state recipes under 'integrate' in {game.info.source}; found none. "
            f"Add one per state (see retrokit/data/integrate.py)."
        )
    wanted = list(known) if names is None else names
    outcomes = []
    folder = game.folders[0]
    for name in wanted:
        if name not in known:
            raise StateNotFoundError(f"Expected a state with a recipe ({', '.join(known)}), got {name!r}." + did_you_mean(name, known))
        made = make_state(game, known[name])
        path = folder / f"{name}.state"
        if not path.exists():
            write_state(path, made)
            outcomes.append(Outcome(name, "made", path))
        elif fingerprint(game, read_state(path)) == fingerprint(game, made):
            outcomes.append(Outcome(name, "up to date", path))
        elif force:
            write_state(path, made, overwrite=True)
            outcomes.append(Outcome(name, "replaced", path))
        else:
            outcomes.append(Outcome(name, "differs", path))
    return outcomes
