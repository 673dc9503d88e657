"""Registering every known game with Gymnasium as ``retrokit/<Game>``.

``gymnasium.make("retrokit/Airstriker-Genesis", state=..., ...)`` then works
after ``import retrokit`` (or with the id ``"retrokit:retrokit/<Game>"``,
which imports retrokit first), and ``gymnasium.make_vec(..., num_envs=N)``
gives retrokit's threaded vector env unless another vectorization mode is asked for.
"""

from __future__ import annotations

import gymnasium

from retrokit.data.games import list_games

NAMESPACE = "retrokit"


def register_envs() -> int:
    """Register every game not registered yet; return how many were added."""
    added = 0
    for game in list_games():
        env_id = f"{NAMESPACE}/{game.name}"
        if env_id in gymnasium.registry:
            continue
        gymnasium.register(
            id=env_id,
            entry_point="retrokit.envs.env:RetroEnv",
            vector_entry_point="retrokit.envs.vector:make_vec",
            kwargs={"game": game.name},
        )
        added += 1
    return added
