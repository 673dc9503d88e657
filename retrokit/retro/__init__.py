"""stable-retro's names and behaviours over retrokit: ``import retrokit.retro as retro`` in its place.

A script written for stable-retro (``import stable_retro as retro``) runs with that one
import changed: ``retro.make``, ``RetroEnv``, ``State``, ``Actions``, ``Observations``,
``Movie``, ``RetroEmulator`` and ``retro.data`` take stable-retro's arguments and do
what stable-retro's do, over retrokit's env, movies, checked states and game resolver
(``docs/from-stable-retro.md``, "retrokit.retro"). What retrokit cannot do fails in one
line that says what to use instead.
"""

from __future__ import annotations

import os
from pathlib import Path

from retrokit.host.systems import system_for_extension
from retrokit.retro import data
from retrokit.retro.emulator import RetroEmulator
from retrokit.retro.enums import Actions, Observations, State
from retrokit.retro.env import RetroEnv, make
from retrokit.retro.missing import missing_names
from retrokit.retro.movie import Movie

__version__ = "1.0.1"  # the stable-retro version whose names and behaviours this follows

__all__ = [
    "Actions", "Movie", "Observations", "RetroEmulator", "RetroEnv", "State", "data", "get_romfile_system", "make",
]  # fmt: skip


def get_romfile_system(rom_path: str | os.PathLike[str]) -> str:
    """The system a ROM file's extension names (``"Genesis"`` for ``.md``).

    Raises:
        UnsupportedSystemError: No system has that extension (with the extensions there are).
    """
    return system_for_extension(Path(rom_path).suffix).name


__getattr__ = missing_names(__name__, {
    "get_core_path": "retrokit.host.cores.find_core(core), or `retrokit cores`",
    "core_path": "`retrokit cores` (the folders searched for cores)",
    "get_system_info": "retrokit.host.systems.get_system(name) (buttons, RAM, screen)",
    "get_fbneo_rom_name": "nothing: retrokit has no FBNeo (arcade) core",
    "is_fbneo_game": "nothing: retrokit has no FBNeo (arcade) core",
})  # stable-retro's names that retrokit.retro does not have, and what to use instead
