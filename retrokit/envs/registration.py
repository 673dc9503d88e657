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

``import retrokit`` does not import Gymnasium (a third of a second), nor list
the game folders: :func:`register_when_gymnasium_loads` registers the ids at
once if Gymnasium is already imported, and else the moment it is, by a hook
on its import. Every way to the registry (``gymnasium.make``,
``gymnasium.registry``, ``gymnasium.spec``) goes through that import, so the
ids are there whenever anyone can look them up.
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import json
import os
import sys
import warnings
from pathlib import Path
from types import ModuleType
from typing import Any

from retrokit.errors import RetrokitError

NAMESPACE = "retrokit"
VERSION = "v0"
_CACHE_LIMIT = 64 << 20  # bytes of the ids' cache read: far above the wheel's thousand games' ids


def game_id(game: str) -> str:
    """The Gymnasium id of a game: ``retrokit/<Game>-v0``."""
    return f"{NAMESPACE}/{game}-{VERSION}"


def level_id(game: str, state: str) -> str:
    """The Gymnasium id of a Sonic benchmark level: ``retrokit/SonicTheHedgehog-GreenHillZone.Act1-v0``."""
    return f"{NAMESPACE}/{game.removesuffix('-Genesis')}-{state}-{VERSION}"


def register_envs() -> int:
    """Register every game and Sonic level not registered yet; return how many were added."""
    games, levels = known_ids()
    added = 0
    for game in games:
        added += _register(
            game_id(game),
            entry_point="retrokit.envs.env:make",
            vector_entry_point="retrokit.envs.vector:make_vec",
            kwargs={"game": game},
        )
    for game, state in levels:
        added += _register(
            level_id(game, state), entry_point="retrokit.envs.sonic:make", kwargs={"game": game, "state": state}
        )
    return added


def known_ids() -> tuple[list[str], list[tuple[str, str]]]:
    """Every game's name and every Sonic level, as the game folders say now.

    Listing the 1,031 game folders and reading the Sonic games' data files
    takes a few tenths of a second, so the answer is kept in
    ``<data>/cache/gymnasium-ids.json`` with what it was made from: the
    search folders, the name and modification time of everything in them
    (a data file added to or removed from a game folder changes the
    folder's time), and the time and size of the Sonic games' data files.
    Any change there, and the folders are read again.
    """
    from retrokit import paths
    from retrokit.errors import FileSystemError

    key = _fingerprint(paths.game_search_dirs())
    try:  # never through a link, never more than a cap: a link to /dev/zero would never end
        cache = paths.records_dir("cache") / "gymnasium-ids.json"
        kept = json.loads(paths.read_regular_file(cache, "the Gymnasium ids' cache", _CACHE_LIMIT, follow=False))
        if kept["key"] == key:
            return kept["games"], [(game, state) for game, state in kept["levels"]]
    except (FileSystemError, ValueError, KeyError, TypeError):  # none yet, or unreadable: made again
        pass
    from retrokit.data.games import list_games
    from retrokit.data.sonic_levels import levels

    games, found = [game.name for game in list_games()], levels()
    try:
        cache = paths.records_dir("cache") / "gymnasium-ids.json"
        paths.atomic_write(cache, json.dumps({"key": key, "games": games, "levels": found}).encode(), overwrite=True)
    except FileSystemError:  # a read-only data folder: the ids are the same, only slower next time
        pass
    return games, found


def _fingerprint(dirs: list[Path]) -> list[Any]:
    """What the ids are made from: each search folder's entries with their modification times, and the
    Sonic games' data files' times and sizes."""
    from retrokit.data.sonic_levels import GAMES

    sonic = {*GAMES, *(f"{game}-v0" for game in GAMES)}
    key: list[Any] = []
    for directory in dirs:
        entries: list[Any] = []
        try:
            with os.scandir(directory) as scan:
                for entry in scan:
                    entries.append([entry.name, _mtime(entry.path)])
                    if entry.name in sonic:
                        entries.append([_mtime(os.path.join(entry.path, name), size=True) for name in _DATA_FILES])
        except OSError as exc:  # listing it fails again when the ids are made, with the reason
            entries.append(str(exc))
        key.append([str(directory), sorted(entries, key=str)])
    return key


_DATA_FILES = ("game.yaml", "data.json", "metadata.json", "rom.sha")


def _mtime(path: str, size: bool = False) -> list[int] | int:
    try:
        found = os.stat(path)
    except OSError:
        return -1
    return [found.st_mtime_ns, found.st_size] if size else found.st_mtime_ns


def _register(env_id: str, **spec: Any) -> int:
    from gymnasium.envs.registration import EnvSpec, registry

    if env_id in registry:
        return 0
    # Straight into the registry: gymnasium.register() compares each new id with every one registered
    # (a third of a second for 1,089), to catch clashes of versioned and unversioned ids that ours,
    # all "-v0" in a namespace of their own, cannot have.
    registry[env_id] = EnvSpec(id=env_id, **spec)
    return 1


class _GymnasiumHook(importlib.abc.MetaPathFinder):
    """Registers the ids right after Gymnasium's own ``__init__`` ran, the first time it is imported."""

    def find_spec(self, name: str, path: Any = None, target: ModuleType | None = None) -> Any:
        if name != "gymnasium":
            return None
        _remove_hook()
        spec = importlib.machinery.PathFinder.find_spec(name, path)
        loader = getattr(spec, "loader", None)
        if loader is None or not hasattr(loader, "exec_module"):
            return spec
        run = loader.exec_module

        def exec_module(module: ModuleType) -> None:
            run(module)
            try:
                register_envs()
            except (RetrokitError, OSError) as exc:  # a broken game folder must not break `import gymnasium`
                warnings.warn(f"retrokit registered no Gymnasium ids: {exc}", stacklevel=2)

        loader.exec_module = exec_module  # this spec's own loader, made for this import only
        return spec


def _remove_hook() -> None:
    sys.meta_path[:] = [finder for finder in sys.meta_path if not isinstance(finder, _GymnasiumHook)]


def register_when_gymnasium_loads() -> None:
    """Register the ids now if Gymnasium is imported, else as soon as it is."""
    if "gymnasium" in sys.modules:
        register_envs()
    elif not any(isinstance(finder, _GymnasiumHook) for finder in sys.meta_path):
        sys.meta_path.insert(0, _GymnasiumHook())
