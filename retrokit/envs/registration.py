"""Registering every known game, and every Sonic benchmark level, with Gymnasium.

Ids carry a version, as Gymnasium's conventions ask, so a future change of an
env's rules can take a new one:

- ``retrokit/<Game>-v0`` for every game, e.g. ``retrokit/Airstriker-Genesis-v0``:
  ``gymnasium.make(id, state=..., frameskip=...)`` is ``retrokit.make(game, ...)``,
  with the same argument checks.
- ``retrokit/<Sonic game>-<Level>-v0`` for the 58 levels of the Sonic benchmark,
  e.g. ``retrokit/SonicTheHedgehog-GreenHillZone.Act1-v0``: the preset of
  :mod:`retrokit.envs.sonic` (the contest rules, the 7 actions).

They exist after ``import retrokit`` (or with the id ``"retrokit:retrokit/<Game>-v0"``,
which imports retrokit first). ``gymnasium.make_vec(id, num_envs=N)`` on a game's
id gives retrokit's threaded vector env unless another vectorization mode is asked for.
"""

from __future__ import annotations

import gymnasium

from retrokit.data.games import list_games
from retrokit.data.sonic_levels import levels

NAMESPACE = "retrokit"
VERSION = "v0"


def game_id(game: str) -> str:
    """The Gymnasium id of a game: ``retrokit/<Game>-v0``."""
    return f"{NAMESPACE}/{game}-{VERSION}"


def level_id(game: str, state: str) -> str:
    """The Gymnasium id of a Sonic benchmark level: ``retrokit/SonicTheHedgehog-GreenHillZone.Act1-v0``."""
    return f"{NAMESPACE}/{game.removesuffix('-Genesis')}-{state}-{VERSION}"


def register_envs() -> int:
    """Register every game and Sonic level not registered yet; return how many were added."""
    added = 0
    for game in list_games():
        added += _register(
            game_id(game.name),
            entry_point="retrokit.envs.env:make",
            vector_entry_point="retrokit.envs.vector:make_vec",
            kwargs={"game": game.name},
        )
    for game, state in levels():
        added += _register(
            level_id(game, state), entry_point="retrokit.envs.sonic:make", kwargs={"game": game, "state": state}
        )
    return added


def _register(env_id: str, **spec: object) -> int:
    if env_id in gymnasium.registry:
        return 0
    gymnasium.register(id=env_id, **spec)  # type: ignore[arg-type]
    return 1
