"""stable-retro's ``retro.data``: listing games, states and scenarios, and finding their files, over retrokit's games.

Every name goes through retrokit's one resolver (:func:`retrokit.data.games.find_game`), so
``"Airstriker-Genesis"`` and stable-retro's folder name ``"Airstriker-Genesis-v0"`` are the
same game. Games are listed under the names stable-retro gives them (its folders' names).
An :class:`Integrations` value picks among the stable-retro wheel's folders as stable-retro
does; retrokit's own games (``games/``, the user's data folder, ``RETROKIT_GAMES``) count as stable.
"""

from __future__ import annotations

import os
from enum import Flag
from pathlib import Path

from retrokit import paths
from retrokit.data.games import Game, find_game, stable_retro_name
from retrokit.data.games import list_games as _all_games
from retrokit.errors import GameNotFoundError, InvalidArgumentError
from retrokit.retro.missing import missing_names

__all__ = [
    "Integrations", "add_custom_integration", "add_integrations", "get_file_path", "get_romfile_path",
    "list_games", "list_scenarios", "list_states", "path",
]  # fmt: skip


class Integrations(Flag):
    """Which integration folders to search, as stable-retro's flags; ``DEFAULT`` is the process's choice."""

    STABLE = 1
    EXPERIMENTAL_ONLY = 2
    CONTRIB_ONLY = 4
    CUSTOM_ONLY = 8
    EXPERIMENTAL = 3
    CONTRIB = 5
    CUSTOM = 9
    ALL = 15
    DEFAULT = 16

    @classmethod
    def add_custom_path(cls, path: str | os.PathLike[str]) -> None:
        """Search ``path``, a folder of game folders, before the others (``RETROKIT_GAMES``'s first folder)."""
        folder = str(Path(path).expanduser().resolve())
        _custom.append(Path(folder))
        known = [part for part in os.environ.get(paths.GAMES_ENV, "").split(os.pathsep) if part and part != folder]
        os.environ[paths.GAMES_ENV] = os.pathsep.join([folder, *known])

    @classmethod
    def clear_custom_paths(cls) -> None:
        """Stop searching the folders :meth:`add_custom_path` added."""
        gone = {str(folder) for folder in _custom}
        kept = [part for part in os.environ.get(paths.GAMES_ENV, "").split(os.pathsep) if part and part not in gone]
        os.environ[paths.GAMES_ENV] = os.pathsep.join(kept)
        _custom.clear()

    @property
    def paths(self) -> list[str]:
        """The folders this value searches, as stable-retro names them (custom paths in full)."""
        flags = resolved(self)
        found = [name for bit, name in _WHEEL_KINDS.items() if flags & bit and bit is not Integrations.STABLE]
        found += [str(folder) for folder in _custom] if flags & Integrations.CUSTOM_ONLY else []
        return found + (["stable"] if flags & Integrations.STABLE else [])


_custom: list[Path] = []  # the folders add_custom_path added, in order
_default = [Integrations.STABLE]  # what DEFAULT means in this process (add_integrations widens it)
_WHEEL_KINDS = {
    Integrations.CONTRIB_ONLY: "contrib", Integrations.EXPERIMENTAL_ONLY: "experimental", Integrations.STABLE: "stable",
}  # fmt: skip


def resolved(inttype: Integrations) -> Integrations:
    """``inttype`` with ``DEFAULT`` replaced by what it means now."""
    if inttype & Integrations.DEFAULT:
        return (inttype & ~Integrations.DEFAULT) | _default[0]
    return inttype


def add_integrations(integrations: Integrations) -> None:
    """Widen what ``Integrations.DEFAULT`` searches in this process (``Integrations.ALL``: every folder)."""
    _default[0] = _default[0] | resolved(integrations)


def add_custom_integration(path: str | os.PathLike[str]) -> None:
    """Search ``path``, a folder of game folders, by default from now on."""
    add_integrations(Integrations.CUSTOM_ONLY)
    Integrations.add_custom_path(path)


def _kind(game: Game) -> Integrations:
    """The integration a game's first folder belongs to: one of the wheel's three, custom, or (retrokit's own) stable."""
    parent = game.folders[0].resolve().parent
    for folder in paths.wheel_data_dirs():
        if folder.resolve() == parent:
            return next(bit for bit, name in _WHEEL_KINDS.items() if name == folder.name)
    return Integrations.CUSTOM_ONLY if any(parent == c for c in _custom) else Integrations.STABLE


def list_games(inttype: Integrations = Integrations.DEFAULT) -> list[str]:
    """The games of those integrations, by the names stable-retro gives them (``Airstriker-Genesis-v0``)."""
    flags = resolved(inttype)
    return sorted(stable_retro_name(game.name) for game in _all_games() if _kind(game) & flags)


def list_states(game: str, inttype: Integrations = Integrations.DEFAULT) -> list[str]:
    """The game's state names, without ``.state``.

    Raises:
        GameNotFoundError: No such game (with the closest names).
    """
    return sorted(find_game(game).states)


def list_scenarios(game: str, inttype: Integrations = Integrations.DEFAULT) -> list[str]:
    """The game's scenario names (its ``*.json`` scenarios and retrokit's ``*.yaml`` ones).

    Raises:
        GameNotFoundError: No such game (with the closest names).
    """
    return sorted(find_game(game).scenarios)


def get_file_path(game: str, file: str, inttype: Integrations = Integrations.DEFAULT) -> str | None:
    """The path of the file ``file`` in the game's folders (the first that has it), or ``None``, as in stable-retro.

    Raises:
        InvalidArgumentError: ``file`` leads out of the game's folder (``../``, an absolute path).
    """
    try:
        found = find_game(game, check=False)
    except GameNotFoundError:
        return None
    for folder in found.folders:
        path = folder / file
        if not path.resolve().is_relative_to(folder.resolve()):
            raise InvalidArgumentError(
                f"Expected a file of the game's folder, e.g. 'rom.sha' or 'Level1.state'; got {file!r}, which leads "
                f"out of {folder}. Name a file inside it."
            )
        if path.is_file():
            return str(path)
    return None


def get_romfile_path(game: str, inttype: Integrations = Integrations.DEFAULT) -> str:
    """The game's ROM file.

    Raises:
        GameNotFoundError: No such game.
        RomNotFoundError: Its ROM is not imported (a ``FileNotFoundError``, as stable-retro raises; it says how to import).
    """
    return str(find_game(game).require_rom())


def path(hint: str | None = None) -> str:
    """The folder holding the stable-retro wheel's integration folders (``stable``, ``experimental``, ``contrib``)."""
    root = paths.wheel_dir()
    return str(root / "data") if root is not None else str(paths.user_games_dir())


__getattr__ = missing_names(__name__, {
    "GameData": "env.data (an env's fields), or retrokit.data.games.find_game(game).reader(emulator.space)",
    "get_original_romfile_path": "get_romfile_path(game)",
    "verify_hash": "retrokit validate GAME (it checks the ROM's SHA-1)",
    "get_known_hashes": "retrokit import, which knows every game's SHA-1s",
    "merge": "retrokit import (it copies ROMs into retrokit's data folder)",
    "EMU_EXTENSIONS": "retrokit.host.systems.get_system(name).extensions",
})  # stable-retro's names that retrokit.retro.data does not have, and what to use instead
