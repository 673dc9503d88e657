"""stable-retro's names and behaviours over retrokit: ``import retrokit.retro as retro`` in its place.

A script written for stable-retro (``import stable_retro as retro``) runs with that one
import changed: ``retro.make``, ``RetroEnv``, ``State``, ``Actions``, ``Observations``,
``Movie``, ``RetroEmulator`` and ``retro.data`` take stable-retro's arguments and do
what stable-retro's do, over retrokit's env, movies, checked states and game resolver
(``docs/from-stable-retro.md``, "retrokit.retro"). What retrokit cannot do fails in one
line that says what to use instead.
"""

from __future__ import annotations

from retrokit.retro import data
from retrokit.retro.emulator import RetroEmulator
from retrokit.retro.enums import Actions, Observations, State
from retrokit.retro.env import RetroEnv, make
from retrokit.retro.movie import Movie

__version__ = "1.0.1"  # the stable-retro version whose names and behaviours this follows

__all__ = ["Actions", "Movie", "Observations", "RetroEmulator", "RetroEnv", "State", "data", "make"]
