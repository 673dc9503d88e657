"""retrokit: emulated console games as reinforcement-learning environments.

``retrokit.make(game, state, scenario, **options)`` makes a Gymnasium env;
``retrokit.make_vec`` steps several on threads; ``retrokit.multiplayer`` has
the PettingZoo envs of two-player games; ``retrokit.sonic`` is the Sonic
benchmark preset.
"""

from __future__ import annotations

from retrokit.env import RetroEnv, State, make
from retrokit.registration import register_envs
from retrokit.vector import ThreadedVectorEnv, make_vec

__version__ = "0.1.0"
__all__ = ["RetroEnv", "State", "ThreadedVectorEnv", "make", "make_vec", "register_envs"]

register_envs()
