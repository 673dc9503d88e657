"""Games: finding integration folders, and their states, scenarios and ROMs.

A game is named ``<Name>-<System>`` and lives in a folder of that name in one
of the search folders of :func:`retrokit.paths.game_search_dirs`. stable-retro's
``<Name>-<System>-v0`` folders are found as ``<Name>-<System>``. The folder's
data file (``game.yaml``, or Gym Retro's ``data.json``, ``metadata.json`` and
``rom.sha``) is read by :mod:`retrokit.data.gamefiles`.

When several search folders hold a game of the same name, the first one's data
file wins and the others add their states and scenarios: so a ``games/`` folder
can use the states of the wheel's folder of the same game. A folder holding
only scenario files (no data file) adds its scenarios to a game found in a
later folder: ``games/1942-Nes/scenario.yaml`` replaces the wheel's Lua
``scenario.json`` while the wheel's data, ROM hashes and states stay in use.

:func:`list_games` only lists folders; a :class:`Game` reads its files the
first time one of its properties is used. :func:`find_game` reads and checks
them at once.
"""

from __future__ import annotations

import fnmatch
import os
import re
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

from retrokit import paths
from retrokit.data import roms
from retrokit.data.gamefiles import GameInfo, data_error, read_game_folder
from retrokit.errors import (
    GameNotFoundError,
    RomMismatchError,
    RomNotFoundError,
    SkippedDataWarning,
    StateNotFoundError,
    UnknownNameError,
    UnsupportedSystemError,
    did_you_mean,
    listed,
)
from retrokit.host.systems import System, get_system

if TYPE_CHECKING:
    from retrokit.host.fields import FieldSpec
    from retrokit.host.memory import AddressSpace, FieldReader

__all__ = [
    "Game",
    "find_game",
    "list_games",
    "load_game",
    "normalize_name",
    "stable_retro_name",
]

STATE_SUFFIX = ".state"
_VERSION_SUFFIX = re.compile(r"-v\d+$")
_NOT_SCENARIOS = {"game.yaml", "data.json", "metadata.json"}


def normalize_name(name: str) -> str:
    """Return a game's name without stable-retro's ``-v0`` suffix."""
    return _VERSION_SUFFIX.sub("", name)


@dataclass(frozen=True)
class Game:
    """A game: its folders, and the data read from them on first use.

    Attributes:
        name: ``<Name>-<System>``, e.g. ``"Airstriker-Genesis"``.
        folders: The game's folders, in search order; the first one's data file is used.
    """

    name: str
    folders: tuple[Path, ...]

    def __reduce__(self) -> tuple[type[Game], tuple[str, tuple[Path, ...]]]:
        # Pickled as its name and folders (an env's arguments may hold a Game): the data read
        # on first use is read again, and its read-only views (MappingProxyType) do not pickle.
        return Game, (self.name, self.folders)

    # --- The data file ----------------------------------------------------------------------

    @cached_property
    def info(self) -> GameInfo:
        """The game's data file, parsed (read on first use): the first of its folders that has one.

        Raises:
            DataFileError: None of its folders has a data file (only a user's folder of states can lack one).
        """
        for folder in self.folders:
            if _is_game_folder(folder):
                return read_game_folder(folder)
        raise data_error(
            self.folders[0], f"a data file (game.yaml) for {self.name}, here or in a shipped game folder of that name",
            "none: this folder of the user's data holds states or scenarios of a game that is not known",
            "rename the folder to a known game's name (retrokit games lists them), or add a game.yaml",
            did_you_mean(self.name, [name for name, folders in _index().items() if any(map(_is_game_folder, folders))]),
        )

    @property
    def system(self) -> System:
        """The game's system, from its data file or else its name's suffix (``-Genesis``).

        Raises:
            UnsupportedSystemError: No known system has that name.
        """
        return get_system(self.info.system or self.name.rsplit("-", 1)[-1])

    @property
    def sha1s(self) -> tuple[str, ...]:
        """The SHA-1s of the ROMs the game accepts (by stable-retro's hashing rules)."""
        return self.info.sha1s

    @property
    def fields(self) -> Mapping[str, FieldSpec]:
        """The game's RAM fields, by name."""
        return self.info.fields

    @property
    def players(self) -> int:
        """How many players the game supports."""
        return self.info.players

    def reader(self, space: AddressSpace) -> FieldReader:
        """The reader of the game's fields over an emulator's memory: the one rule for which fields are read.

        A stable-retro ``data.json``'s field outside the memory (its test data names one per system) is skipped,
        as its ``lookup_all`` skips it, in one :class:`~retrokit.errors.SkippedDataWarning`; a ``game.yaml`` is strict.

        Raises:
            InvalidArgumentError: A field of the game's ``game.yaml`` lies outside the memory.
        """
        from retrokit.host.memory import FieldReader

        fields = self.fields
        if self.info.source.name == "data.json":
            outside = [s for s in fields.values() if not space.holds(s.address, s.field_type.width)]
            if outside:
                warnings.warn(
                    f"{self.info.source}: skipped {len(outside)} field(s) outside the {self.system.name} memory, "
                    f"as stable-retro skips them: {listed(f'{s.name} ({s.address:#x})' for s in outside)}.",
                    SkippedDataWarning, stacklevel=3,
                )
                fields = {name: spec for name, spec in fields.items() if spec not in outside}
        return FieldReader(fields, space)

    @property
    def default_player_states(self) -> tuple[str, ...]:
        """Gym Retro's per-player-count default states: entry ``i`` is for ``i + 1`` players."""
        return self.info.default_player_states

    # --- States ---------------------------------------------------------------------------------

    @cached_property
    def _state_files(self) -> Mapping[str, Path]:
        found: dict[str, Path] = {}
        for folder in self.folders:
            for path in sorted(folder.glob(f"*{STATE_SUFFIX}")):
                found.setdefault(path.name[: -len(STATE_SUFFIX)], path)
        return MappingProxyType(found)

    @property
    def states(self) -> list[str]:
        """The game's state names: the data file's list, else every ``*.state`` not starting with ``_``."""
        if self.info.states is not None:
            return list(self.info.states)
        return sorted(name for name in self._state_files if not name.startswith("_"))

    @property
    def default_state(self) -> str | None:
        """The state an environment starts from unless told otherwise."""
        return self.info.default_state

    def state_path(self, name: str | None = None) -> Path:
        """Return the file of the state ``name`` (by default, :attr:`default_state`).

        ``name`` may end in ``.state``. A path to a ``.state`` file is returned as it is.

        Raises:
            StateNotFoundError: The game has no such state.
        """
        if name is None:
            name = self.default_state
            if name is None:
                raise StateNotFoundError(
                    f"Expected {self.name} to name a default state; found none in its data file. "
                    f"Pass a state name: one of {', '.join(self.states) or '(no states)'}."
                )
        key = name.removesuffix(STATE_SUFFIX)
        if key not in self._state_files:  # a file copied in since the folders were listed: list them again
            self.__dict__.pop("_state_files", None)
        if key in self._state_files:
            return self._state_files[key]
        if name.endswith(STATE_SUFFIX) and (os.sep in name or "/" in name) and Path(name).is_file():
            return Path(name)
        where = ", ".join(str(f) for f in self.folders)
        if key in self.state_recipes:
            raise StateNotFoundError(
                f"Expected the state file {key}{STATE_SUFFIX} in {where}; it has a recipe but has not been made. "
                f"Make it with: retrokit integrate {self.name} {key}"
            )
        raise StateNotFoundError(
            f"Expected a state of {self.name}: one of {', '.join(self.states) or '(none)'}; "
            f"found no file {key}{STATE_SUFFIX} in {where}."
            + did_you_mean(key, self._state_files)
        )

    @property
    def state_recipes(self) -> Mapping[str, Any]:
        """The recipes ``retrokit integrate`` makes states from (raw, from game.yaml's ``integrate``)."""
        recipes = self.info.extra.get("integrate")
        return recipes if isinstance(recipes, Mapping) else {}

    # --- Scenarios ------------------------------------------------------------------------------

    @cached_property
    def scenarios(self) -> Mapping[str, Path]:
        """Scenario files by name: ``*.yaml`` besides ``game.yaml``, and Gym Retro ``*.json``."""
        found: dict[str, Path] = {}
        for folder in self.folders:
            for pattern in ("*.yaml", "*.json"):
                for path in sorted(folder.glob(pattern)):
                    if path.name not in _NOT_SCENARIOS:
                        found.setdefault(path.stem, path)
        return MappingProxyType(found)

    @property
    def default_scenario(self) -> str | None:
        """The scenario used unless told otherwise: ``"scenario"`` if the game has one."""
        return "scenario" if "scenario" in self.scenarios else None

    def scenario_path(self, name: str | None = None) -> Path:
        """Return the file of scenario ``name`` (by default, :attr:`default_scenario`).

        Raises:
            UnknownNameError: The game has no such scenario.
        """
        key = name if name is not None else self.default_scenario
        if key is not None and key in self.scenarios:
            return self.scenarios[key]
        raise UnknownNameError(
            f"Expected a scenario of {self.name}: one of {', '.join(self.scenarios) or '(none)'}; "
            f"found {'no default scenario' if key is None else repr(key)}. Scenario files are "
            f"scenario.yaml or *.json in {self.folders[0]}." + did_you_mean(key or "", self.scenarios)
        )

    # --- ROM ------------------------------------------------------------------------------------

    @property
    def rom_extensions(self) -> tuple[str, ...]:
        """The ROM extensions of the game's system; the first is the one imported ROMs get."""
        return self.system.extensions

    def imported_rom_path(self, data_dir: str | os.PathLike[str] | None = None) -> Path:
        """Return where an imported ROM of this game is (or would be) stored."""
        return paths.imported_rom_path(self.name, self.rom_extensions[0], data_dir)

    def _rom_candidates(self, data_dir: str | os.PathLike[str] | None) -> list[Path]:
        bundled = [folder / f"rom.{ext}" for folder in self.folders for ext in self.rom_extensions]
        return [p for p in (*bundled, self.imported_rom_path(data_dir)) if p.is_file()]

    def rom_path(self, data_dir: str | os.PathLike[str] | None = None) -> Path | None:
        """Return the game's ROM file, or ``None`` if it is not available.

        A ROM bundled in a game folder is used first, then the imported one, each
        only if its SHA-1 is one the game accepts.
        """
        for path in self._rom_candidates(data_dir):
            if cached_rom_sha1(path, self.system) in self.sha1s:
                return path
        return None

    def require_rom(self, data_dir: str | os.PathLike[str] | None = None) -> Path:
        """Return the game's ROM file.

        Raises:
            RomNotFoundError: The ROM has not been imported; the message says how to.
            RomMismatchError: A ROM file is there, but it is not one the game accepts.
        """
        path = self.rom_path(data_dir)
        if path is not None:
            return path
        if not self.sha1s:
            raise RomNotFoundError(
                f"Expected the data file of {self.name} ({self.info.source}) to list the SHA-1s of its "
                "ROM; found none, so no ROM can be imported or checked for it. Add them (rom.sha, or "
                "'roms' in game.yaml)."
            )
        expected = ", ".join(self.sha1s)
        candidates = self._rom_candidates(data_dir)
        if candidates:
            found = "; ".join(f"{p} has SHA-1 {cached_rom_sha1(p, self.system)}" for p in candidates)
            raise RomMismatchError(
                f"Expected a ROM of {self.name} with SHA-1 {expected}; found {found}. "
                "Delete that file, then import the right ROM with: retrokit import /path/to/your/roms"
            )
        raise RomNotFoundError(
            f"Expected the ROM of {self.name} (the {self.system} ROM with SHA-1 {expected}) "
            f"in {self.imported_rom_path(data_dir)}; found no ROM there. Import it with: "
            "retrokit import /path/to/your/roms (folders and .zip files are searched; "
            "set RETROKIT_DATA to store ROMs elsewhere)."
        )

    # --- Checks ---------------------------------------------------------------------------------

    def check(self) -> Game:
        """Read every data file now and check that they agree; return ``self``.

        Raises:
            DataFileError: A data file is malformed, or names a state that does not exist.
        """
        info = self.info
        if info.states is not None:
            missing = [s for s in info.states if s not in self._state_files]
            if missing:
                raise data_error(
                    info.source, f"state files for the listed states {missing}",
                    f"no such file in {', '.join(map(str, self.folders))}",
                    "add the .state files or remove the names from the list",
                )
        made_or_makeable = set(self._state_files) | set(self.state_recipes)
        if info.default_state is not None and info.default_state not in made_or_makeable:
            raise data_error(
                info.source, f"the default state {info.default_state!r} to be one of the game's states",
                f"{', '.join(self.states) or 'no states'}",
                "fix the default state's name", did_you_mean(info.default_state, self._state_files),
            )
        try:
            self.system  # noqa: B018 -- an unknown system fails here, when the game loads
        except UnsupportedSystemError as exc:
            raise UnsupportedSystemError(f"{info.source}: {exc}") from exc
        return self


# --- Finding games ----------------------------------------------------------------------------

_index_cache: dict[tuple[tuple[str, int], ...], dict[str, tuple[Path, ...]]] = {}


def _is_game_folder(path: Path) -> bool:
    # lexists, not is_file: a data file that is a FIFO, a folder or a symlink loop makes its folder the game's,
    # so reading it fails with the reason instead of the next folder's data file being used without a word.
    return any(os.path.lexists(path / marker) for marker in ("game.yaml", "rom.sha", "data.json"))


def _is_folder(entry: os.DirEntry[str]) -> bool:
    """Whether a search folder's entry is a folder; a symlink loop is not (it cannot be read as one)."""
    try:
        return entry.is_dir()
    except OSError:  # ELOOP: a link to itself must not break every command
        return False


def _is_scenario_folder(path: Path) -> bool:
    """Whether a folder without a data file holds scenario files (to add to a game found elsewhere)."""
    return any(p.name not in _NOT_SCENARIOS for pattern in ("*.yaml", "*.json") for p in path.glob(pattern))


def _index() -> dict[str, tuple[Path, ...]]:
    """Map each game name to its folders, in search order (cached until a search folder changes)."""
    dirs = paths.game_search_dirs()
    key = tuple((str(d), d.stat().st_mtime_ns) for d in dirs)
    if key in _index_cache:
        return _index_cache[key]
    index: dict[str, list[Path]] = {}
    has_data: set[str] = set()
    user = paths.user_games_dir()
    for directory in dirs:
        with os.scandir(directory) as entries:
            for entry in sorted(entries, key=lambda e: e.name):
                if entry.name[:1] in "._" or not _is_folder(entry):
                    continue
                path, name = Path(entry.path), normalize_name(entry.name)
                if _is_game_folder(path):
                    has_data.add(name)
                elif directory == user:
                    # A user's folder may hold only states and scenarios for a shipped game; one that
                    # matches no game is kept too, so that it fails loudly instead of being ignored.
                    has_data.add(name)
                elif not _is_scenario_folder(path):
                    continue
                index.setdefault(name, []).append(path)
    # A name with scenario folders only is no game: nothing says its system, ROM or fields.
    result = {name: tuple(folders) for name, folders in sorted(index.items()) if name in has_data}
    _index_cache.clear()
    _index_cache[key] = result
    return result


def stable_retro_name(name: str) -> str:
    """The name stable-retro knows a game by, which it writes as a movie's ``GameName`` and looks the game up by.

    Its integration folder's name (a folder with a ``rom.sha``): ``Airstriker-Genesis-v0`` in its ``stable``
    folder, ``ActRaiser2-Snes`` (no ``-v0``) in ``experimental``, ``contrib`` or a custom path; the first such
    folder of the game's. Else (retrokit's own ``game.yaml`` games) ``<Name>-<System>-v0``, as its stable games.
    """
    key = normalize_name(name)
    for folder in _index().get(key, ()):
        if os.path.lexists(folder / "rom.sha"):
            return folder.name
    return f"{key}-v0"


def list_games(pattern: str | None = None) -> list[Game]:
    """Return every known game, sorted by name; their files are read on first use.

    Args:
        pattern: Keep only names matching this glob (``"Sonic*"``), or containing
            it if it has no wildcard; case-insensitive.
    """
    games = [Game(name, folders) for name, folders in _index().items()]
    if pattern is None:
        return games
    glob = pattern if any(c in pattern for c in "*?[") else f"*{pattern}*"
    return [g for g in games if fnmatch.fnmatch(g.name.lower(), glob.lower())]


def load_game(folder: str | os.PathLike[str], *extra_folders: str | os.PathLike[str]) -> Game:
    """Load and check the game in the folder ``folder`` only (either format), with optional extra state folders.

    To turn what a user typed (a name or a folder) into a game, use :func:`find_game`.

    Raises:
        GameNotFoundError: ``folder`` holds no data file.
        DataFileError: A data file is malformed.
    """
    folder = Path(folder)
    if not folder.is_dir() or not _is_game_folder(folder):
        raise GameNotFoundError(
            f"Expected a game folder holding game.yaml, or data.json and rom.sha; found "
            f"{'no such folder' if not folder.is_dir() else 'neither'} at {str(folder)!r}."
        )
    return Game(normalize_name(folder.resolve().name), (folder, *map(Path, extra_folders))).check()


def find_game(name: Game | str | os.PathLike[str], *, check: bool = True) -> Game:
    """The one answer to "which game does this mean": a :class:`Game`, a name, or a game folder.

    A name is ``"Airstriker-Genesis"`` or ``"Airstriker-Genesis-v0"``, looked
    up in the search folders first; else a folder holding a data file
    (``game.yaml``, or ``data.json`` and ``rom.sha``: ``.`` is the current one)
    is that folder's game.

    Args:
        name: The game, its name, or its folder.
        check: Read and check its data files now (``retrokit validate`` checks them as a step of its own).

    Raises:
        GameNotFoundError: No search folder holds a game of that name, and it is no game folder.
        DataFileError: The game's data file is malformed (with ``check``).
    """
    if isinstance(name, Game):
        return name.check() if check else name
    name = os.fspath(name)
    index = _index()
    key = normalize_name(name)
    if key not in index:  # a name in other case is that game, when only one game has it
        same = [known for known in index if known.lower() == key.lower()]
        key = same[0] if len(same) == 1 else key
    if key in index:
        game = Game(key, index[key])
        return game.check() if check else game
    folder = Path(name)
    if os.path.isdir(folder) and _is_game_folder(folder):  # os.path's: False, not an error, for a name too long
        game = Game(normalize_name(folder.resolve().name), (folder,))
        return game.check() if check else game
    dirs = paths.game_search_dirs()
    missing = [str(d) for d in paths.env_games_dirs() if not d.is_dir()]
    note = f" {paths.GAMES_ENV} names folders that do not exist: {', '.join(missing)}." if missing else ""
    where = f"in the {len(dirs)} integration folders" if dirs else "(no integration folder: is stable-retro installed?)"
    raise GameNotFoundError(
        f"Expected the name of a known game, <Name>-<System>; found {name!r}, which is no game {where}.{note}"
        + did_you_mean(key, index) + " List the games with: retrokit games [PATTERN]."
    )


# --- ROM hashes, cached per file version --------------------------------------------------------

_sha1_cache: dict[tuple[str, int, int, str], str] = {}


def cached_rom_sha1(path: Path, system: System | str) -> str:
    """Return a ROM file's SHA-1 (stable-retro's rules), hashed once per file version."""
    system = get_system(system)
    stat = path.stat()
    key = (str(path), stat.st_size, stat.st_mtime_ns, system.name)
    if key not in _sha1_cache:
        _sha1_cache[key] = roms.rom_sha1(path, system)
    return _sha1_cache[key]
