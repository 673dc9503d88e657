"""Games: finding integration folders and reading their data files.

A game is named ``<Name>-<System>`` and lives in a folder of that name in one
of the search folders of :func:`retrokit.paths.game_search_dirs`. Two folder
formats are read:

- retrokit's: ``game.yaml`` (see ``docs/architecture.md``), ``*.state``,
  scenario ``*.yaml`` files and, for free games, ``rom.<ext>``.
- Gym Retro's and stable-retro's: ``data.json``, ``metadata.json``,
  ``rom.sha``, ``*.state`` and scenario ``*.json`` files. stable-retro's
  ``<Name>-<System>-v0`` folders are found as ``<Name>-<System>``.

When several search folders hold a game of the same name, the first one's data
file wins and the others add their states and scenarios: so a ``games/`` folder
can use the states of the wheel's folder of the same game.

:func:`list_games` only lists folders; a :class:`Game` reads its files the
first time one of its properties is used. :func:`find_game` reads and checks
them at once.
"""

from __future__ import annotations

import fnmatch
import json
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

from retrokit import paths, roms
from retrokit.errors import (
    DataFileError,
    FieldTypeError,
    GameNotFoundError,
    RomMismatchError,
    RomNotFoundError,
    StateNotFoundError,
    UnknownNameError,
    UnsupportedSystemError,
    did_you_mean,
)

if TYPE_CHECKING:
    from retrokit.memory import FieldSpec

__all__ = [
    "Game",
    "GameInfo",
    "find_game",
    "list_games",
    "load_game",
    "normalize_name",
    "read_game_folder",
    "read_game_yaml",
    "read_gym_retro_folder",
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

    # --- The data file ----------------------------------------------------------------------

    @cached_property
    def info(self) -> GameInfo:
        """The game's data file, parsed (read on first use)."""
        return read_game_folder(self.folders[0])

    @property
    def system(self) -> str:
        """The system's name, e.g. ``"Genesis"``."""
        return self.info.system or self.name.rsplit("-", 1)[-1]

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
        key = name[: -len(STATE_SUFFIX)] if name.endswith(STATE_SUFFIX) else name
        if key in self._state_files:
            return self._state_files[key]
        if name.endswith(STATE_SUFFIX) and (os.sep in name or "/" in name) and Path(name).is_file():
            return Path(name)
        where = ", ".join(str(f) for f in self.folders)
        raise StateNotFoundError(
            f"Expected a state of {self.name}: one of {', '.join(self.states) or '(none)'}; "
            f"found no file {key}{STATE_SUFFIX} in {where}."
            + did_you_mean(key, self._state_files)
        )

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
        ext = roms.system_extension(self.system)
        return (ext, *(e for e in roms.system_extensions()[self.system] if e != ext))

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
            if _cached_sha1(path, self.system) in self.sha1s:
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
            found = "; ".join(f"{p} has SHA-1 {_cached_sha1(p, self.system)}" for p in candidates)
            raise RomMismatchError(
                f"Expected a ROM of {self.name} with SHA-1 {expected}; found {found}. "
                "Delete that file, then import the right ROM with: retrokit import /path/to/your/roms"
            )
        raise RomNotFoundError(
            f"Expected the ROM of {self.name} (a {self.system} ROM with SHA-1 {expected}) "
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
                raise _data_error(
                    info.source, f"state files for the listed states {missing}",
                    f"no such file in {', '.join(map(str, self.folders))}",
                    "add the .state files or remove the names from the list",
                )
        if info.default_state is not None and info.default_state not in self._state_files:
            raise _data_error(
                info.source, f"the default state {info.default_state!r} to be one of the game's states",
                f"{', '.join(self.states) or 'no states'}",
                "fix the default state's name", did_you_mean(info.default_state, self._state_files),
            )
        try:
            roms.system_extension(self.system)
        except UnsupportedSystemError as exc:
            raise UnsupportedSystemError(f"{info.source}: {exc}") from exc
        return self


# --- Finding games ----------------------------------------------------------------------------

_index_cache: dict[tuple[tuple[str, int], ...], dict[str, tuple[Path, ...]]] = {}


def _is_game_folder(path: Path) -> bool:
    return any((path / marker).is_file() for marker in ("game.yaml", "rom.sha", "data.json"))


def _index() -> dict[str, tuple[Path, ...]]:
    """Map each game name to its folders, in search order (cached until a search folder changes)."""
    dirs = paths.game_search_dirs()
    key = tuple((str(d), d.stat().st_mtime_ns) for d in dirs)
    if key in _index_cache:
        return _index_cache[key]
    index: dict[str, list[Path]] = {}
    for directory in dirs:
        with os.scandir(directory) as entries:
            for entry in sorted(entries, key=lambda e: e.name):
                if entry.name[:1] in "._" or not entry.is_dir():
                    continue
                path = Path(entry.path)
                if _is_game_folder(path):
                    index.setdefault(normalize_name(entry.name), []).append(path)
    result = {name: tuple(folders) for name, folders in sorted(index.items())}
    _index_cache.clear()
    _index_cache[key] = result
    return result


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
    """Load and check the game in ``folder`` (either format), with optional extra state folders.

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


def find_game(name: str) -> Game:
    """Return the game called ``name`` (``"Airstriker-Genesis"`` or ``"Airstriker-Genesis-v0"``).

    Its data files are read and checked now. A path to a game folder also works.

    Raises:
        GameNotFoundError: No search folder holds a game of that name.
        DataFileError: The game's data file is malformed.
    """
    index = _index()
    key = normalize_name(name)
    if key in index:
        return Game(key, index[key]).check()
    if (os.sep in name or "/" in name) and Path(name).is_dir():
        return load_game(name)
    searched = ", ".join(str(d) for d in paths.game_search_dirs()) or "(none: is stable-retro installed?)"
    missing = [str(d) for d in paths.env_games_dirs() if not d.is_dir()]
    note = f" {paths.GAMES_ENV} names folders that do not exist: {', '.join(missing)}." if missing else ""
    raise GameNotFoundError(
        f"Expected the name of a known game, <Name>-<System>; found {name!r}, which no folder in "
        f"{searched} holds.{note} List the games with: retrokit games." + did_you_mean(key, index)
    )


# --- ROM hashes, cached per file version --------------------------------------------------------

_sha1_cache: dict[tuple[str, int, int, str], str] = {}


def _cached_sha1(path: Path, system: str) -> str:
    stat = path.stat()
    key = (str(path), stat.st_size, stat.st_mtime_ns, system)
    if key not in _sha1_cache:
        _sha1_cache[key] = roms.rom_sha1(path, system)
    return _sha1_cache[key]



# --- Data files -------------------------------------------------------------------------------


@dataclass(frozen=True)
class GameInfo:
    """What a game's data file says (``game.yaml``, or Gym Retro's JSON files).

    Attributes:
        source: The data file (``game.yaml`` or ``data.json``).
        system: The system named by the data file, or ``None`` for the folder's suffix.
        sha1s: The SHA-1s of acceptable ROMs, lowercase.
        fields: RAM fields by name.
        default_state: The default state's name.
        states: The listed state names, or ``None`` to use every ``*.state`` file.
        players: How many players the game supports.
        default_player_states: Gym Retro's default state per player count.
        title: A human-readable title.
        original_rom_name: The file name an FBNeo core needs (``metadata.json``).
        extra: Other top-level entries, for other layers (tags, notes, ...).
    """

    source: Path
    system: str | None
    sha1s: tuple[str, ...]
    fields: Mapping[str, FieldSpec]
    default_state: str | None = None
    states: tuple[str, ...] | None = None
    players: int = 1
    default_player_states: tuple[str, ...] = ()
    title: str | None = None
    original_rom_name: str | None = None
    extra: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))


_YAML_KEYS = ("system", "title", "roms", "fields", "states", "players")
_FIELD_KEYS = ("address", "type", "mask")
_SHA1 = re.compile(r"^[0-9a-fA-F]{40}$")


def _data_error(source: Path | str, expected: str, found: str, fix: str, hint: str = "") -> DataFileError:
    return DataFileError(f"{source}: expected {expected}; found {found}. To fix it, {fix}.{hint}")


def _describe(value: Any) -> str:
    text = repr(value)
    return f"{type(value).__name__} {text if len(text) <= 60 else text[:57] + '...'}"


def _expect(source: Path, where: str, value: Any, kind: type | tuple[type, ...], what: str) -> Any:
    if isinstance(value, kind) and not (isinstance(value, bool) and kind is not bool):
        return value
    raise _data_error(source, f"{where} to be {what}", _describe(value), f"write {where} as {what}")


def _check_keys(source: Path, where: str, mapping: Mapping[str, Any], allowed: tuple[str, ...]) -> None:
    for key in mapping:
        if key not in allowed:
            raise _data_error(
                source, f"{where} to have only the keys {', '.join(allowed)}", f"the key {key!r}",
                "rename or remove it", did_you_mean(str(key), allowed),
            )


def _int(source: Path, where: str, value: Any) -> int:
    if isinstance(value, str):
        try:
            return int(value, 0)
        except ValueError:
            pass
    return _expect(source, where, value, int, "an integer (e.g. 0xFF0010)")


def _field(source: Path, name: str, entry: Any) -> FieldSpec:
    from retrokit.memory import FieldSpec

    where = f"field {name!r}"
    entry = _expect(source, where, entry, Mapping, "a mapping with address, type and optionally mask")
    _check_keys(source, where, entry, _FIELD_KEYS)
    for key in ("address", "type"):
        if key not in entry:
            raise _data_error(source, f"{where} to have {key!r}", f"the keys {sorted(entry)}", f"add its {key}")
    address = _int(source, f"the address of {where}", entry["address"])
    code = _expect(source, f"the type of {where}", entry["type"], str, "a type code string such as '>u2'")
    mask = None if entry.get("mask") is None else _int(source, f"the mask of {where}", entry["mask"])
    if address < 0:  # masks may be negative: Gym Retro's are two's complement (Amidar-Atari2600)
        raise _data_error(source, f"{where} to have a non-negative address", repr(entry), "fix the address")
    try:
        return FieldSpec(name, address, code, mask)
    except FieldTypeError as exc:  # the type code; FieldSpec parses it
        raise FieldTypeError(f"{source}: {where}: {exc}") from exc


def _fields(source: Path, where: str, value: Any) -> Mapping[str, FieldSpec]:
    value = _expect(source, where, value if value is not None else {}, Mapping, "a mapping of field names")
    return MappingProxyType({str(name): _field(source, str(name), entry) for name, entry in value.items()})


def _sha1(source: Path, where: str, value: Any) -> str:
    if not isinstance(value, str) or not _SHA1.match(value.strip()):
        raise _data_error(source, f"{where} to be a SHA-1 of 40 hex digits", _describe(value), "fix the hash")
    return value.strip().lower()


def _names(source: Path, where: str, value: Any) -> tuple[str, ...]:
    items = _expect(source, where, value, list, "a list of names")
    return tuple(_expect(source, f"each of {where}", item, str, "a name") for item in items)


def read_game_yaml(path: str | os.PathLike[str]) -> GameInfo:
    """Read a retrokit ``game.yaml``.

    Raises:
        DataFileError: The file is not valid YAML or does not follow the format.
        FieldTypeError: A field's type code is not one retrokit reads.
    """
    import yaml

    source = Path(path)
    try:
        doc = yaml.load(source.read_text(encoding="utf-8"), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or exc
        raise _data_error(source, "valid YAML", f"a syntax error{at}: {problem}", "fix the YAML syntax") from exc
    except (OSError, UnicodeDecodeError) as exc:
        raise _data_error(source, "a readable UTF-8 file", str(exc), "check the file") from exc
    doc = _expect(source, "the file", doc, dict, "a mapping (system, roms, fields, states, players)")
    extra = {k: v for k, v in doc.items() if k not in _YAML_KEYS}
    for key in extra:
        if did_you_mean(str(key), _YAML_KEYS):  # a typo of a known key
            _check_keys(source, "the file", doc, _YAML_KEYS)
    roms_list = _expect(source, "'roms'", doc.get("roms", []), list, "a list of {sha1: ..., label: ...}")
    sha1s = tuple(
        _sha1(source, "each rom", r.get("sha1") if isinstance(r, Mapping) else r) for r in roms_list
    )
    states = _expect(source, "'states'", doc.get("states") or {}, Mapping, "a mapping with default and list")
    _check_keys(source, "'states'", states, ("default", "list"))
    default = states.get("default")
    players = _expect(source, "'players'", doc.get("players", 1), int, "a positive integer")
    system = doc.get("system")
    return GameInfo(
        source=source,
        system=None if system is None else _expect(source, "'system'", system, str, "a system name"),
        sha1s=sha1s,
        fields=_fields(source, "'fields'", doc.get("fields")),
        default_state=None if default is None else _expect(source, "the default state", default, str, "a name"),
        states=None if states.get("list") is None else _names(source, "the state list", states["list"]),
        players=_positive(source, players),
        title=doc.get("title"),
        extra=MappingProxyType(extra),
    )


def _positive(source: Path, players: int) -> int:
    if players < 1:
        raise _data_error(source, "'players' to be at least 1", str(players), "fix the player count")
    return players


def _read_json(path: Path, required: bool) -> dict[str, Any]:
    if not path.is_file() and not required:
        return {}
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise _data_error(
            path, "valid JSON", f"a syntax error at line {exc.lineno}, column {exc.colno}: {exc.msg}",
            "fix the JSON syntax",
        ) from exc
    except (OSError, UnicodeDecodeError) as exc:
        raise _data_error(path, "a readable UTF-8 JSON file", str(exc), "check the file") from exc
    return _expect(path, "the file", doc, dict, "a JSON object")


def read_gym_retro_folder(folder: str | os.PathLike[str]) -> GameInfo:
    """Read a Gym Retro / stable-retro integration folder: data.json, metadata.json, rom.sha.

    Raises:
        DataFileError: A file is not valid JSON or does not follow the format.
        FieldTypeError: A field's type code is not one retrokit reads.
    """
    folder = Path(folder)
    data_path, meta_path, sha_path = folder / "data.json", folder / "metadata.json", folder / "rom.sha"
    data = _read_json(data_path, required=data_path.exists())
    _check_keys(data_path, "the file", data, ("info",))
    meta = _read_json(meta_path, required=False)
    sha1s: tuple[str, ...] = ()
    if sha_path.is_file():
        lines = [line.strip() for line in sha_path.read_text(encoding="utf-8", errors="replace").splitlines()]
        sha1s = tuple(_sha1(sha_path, f"line {i + 1}", line) for i, line in enumerate(lines) if line)
    per_player = _names(meta_path, "'default_player_state'", meta.get("default_player_state", []))
    players = _expect(meta_path, "'players'", meta.get("players", max(1, len(per_player))), int, "an integer")
    known = ("default_state", "default_player_state", "players", "system", "title", "original_rom_name")
    default = meta.get("default_state")
    return GameInfo(
        source=data_path,
        system=meta.get("system"),
        sha1s=sha1s,
        fields=_fields(data_path, "'info'", data.get("info")),
        default_state=None if default is None else _expect(meta_path, "'default_state'", default, str, "a name"),
        players=_positive(meta_path, players),
        default_player_states=per_player,
        title=meta.get("title"),
        original_rom_name=meta.get("original_rom_name"),
        extra=MappingProxyType({k: v for k, v in meta.items() if k not in known}),
    )


def read_game_folder(folder: str | os.PathLike[str]) -> GameInfo:
    """Read a game folder's data file: ``game.yaml`` if there is one, else Gym Retro's files."""
    folder = Path(folder)
    if (folder / "game.yaml").is_file():
        return read_game_yaml(folder / "game.yaml")
    return read_gym_retro_folder(folder)
