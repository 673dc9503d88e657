"""What ``make(game, state, scenario)`` means, answered once: the game, its ROM, the checked state, the scenario.

An env (and any tool that plays a game) takes a :class:`Resolved`, made here
by :func:`resolve` from what the user gave in any of its forms:

- the game: a :class:`~retrokit.data.games.Game`, a name or a folder (:func:`~retrokit.data.games.find_game`);
- the state: :attr:`State.DEFAULT` (the game's default, per player count),
  :attr:`State.NONE` (power-on), a name of the game's states, or a ``.state``
  path; it is loaded through the one checked load
  (:func:`retrokit.data.statecheck.load_state`);
- the scenario: ``None`` (the game's default, if it has one), a name of the
  game's scenarios, a ``.yaml`` / ``.json`` path, or a parsed mapping. The
  data layer finds it; the env compiles it (the language is a layer above).
"""

from __future__ import annotations

import enum
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from retrokit.data.games import Game, find_game
from retrokit.data.statecheck import load_state
from retrokit.host.emulator import VettedState

SCENARIO_SUFFIXES = (".yaml", ".yml", ".json")


class State(enum.Enum):
    """Special start states, as in Gym Retro."""

    DEFAULT = "default"  #: the game's default state
    NONE = "none"  #: power on, no state


@dataclass(frozen=True)
class StartState:
    """Where episodes start: a checked state and its name, or power-on (both ``None``)."""

    name: str | None
    state: VettedState | None


@dataclass(frozen=True)
class Resolved:
    """A game ready to play: everything ``make(game, state, scenario)`` named, found and checked.

    Attributes:
        game: The game.
        rom: Its ROM file.
        start: The start state (checked) and its name.
        scenario: The scenario's file or mapping, or ``None`` for none.
    """

    game: Game
    rom: Path
    start: StartState
    scenario: Path | Mapping[str, Any] | None


def resolve(
    game: Game | str | os.PathLike[str],
    state: str | os.PathLike[str] | State | None = State.DEFAULT,
    scenario: str | os.PathLike[str] | Mapping[str, Any] | None = None,
    *,
    players: int = 1,
) -> Resolved:
    """Find the game, its ROM, its start state (checked) and its scenario.

    Raises:
        GameNotFoundError: No such game.
        RomNotFoundError: The game's ROM has not been imported.
        StateNotFoundError: The game has no such state.
        StateError: The state is not one the core can run for this game.
        ScenarioError: The game has no such scenario.
    """
    found = find_game(game)
    rom = found.require_rom()
    return Resolved(found, rom, resolve_state(found, state, players=players), resolve_scenario(found, scenario))


def resolve_state(game: Game, state: str | os.PathLike[str] | State | None, *, players: int = 1) -> StartState:
    """The checked start state that ``state`` names for ``game`` (see :func:`resolve`)."""
    if state is None or state is State.DEFAULT:
        by_players = game.default_player_states
        name = by_players[players - 1] if len(by_players) >= players else game.default_state
        return StartState(name, load_state(game, game.state_path(name))) if name else StartState(None, None)
    if state is State.NONE:
        return StartState(None, None)
    path = Path(state)
    if path.suffix == ".state" and path.is_file():
        return StartState(path.stem, load_state(game, path))
    return StartState(str(state), load_state(game, game.state_path(str(state))))


def resolve_scenario(
    game: Game, scenario: str | os.PathLike[str] | Mapping[str, Any] | None
) -> Path | Mapping[str, Any] | None:
    """The scenario file (or mapping) that ``scenario`` names for ``game``; ``None`` if it has none."""
    if isinstance(scenario, Mapping):
        return scenario
    if scenario is None:
        return None if game.default_scenario is None else game.scenario_path()
    path = Path(scenario)
    if path.suffix in SCENARIO_SUFFIXES and path.is_file():
        return path
    return game.scenario_path(str(scenario))
