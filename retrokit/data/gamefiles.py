"""Game data files: reading a game folder's ``game.yaml`` or Gym Retro JSON files.

Two folder formats are read:

- retrokit's: ``game.yaml`` (see ``docs/architecture.md``), ``*.state``,
  scenario ``*.yaml`` files and, for free games, ``rom.<ext>``.
- Gym Retro's and stable-retro's: ``data.json``, ``metadata.json``,
  ``rom.sha``, ``*.state`` and scenario ``*.json`` files.

This module reads only the data files, into a :class:`GameInfo`; finding game
folders, states, scenarios and ROMs is :mod:`retrokit.data.games`'s job.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

from retrokit.errors import DataFileError, FieldTypeError, FileSystemError, InvalidArgumentError, did_you_mean
from retrokit.paths import read_regular_file

if TYPE_CHECKING:
    from retrokit.host.fields import FieldSpec

__all__ = [
    "GameInfo",
    "data_error",
    "read_game_folder",
    "read_game_yaml",
    "read_gym_retro_folder",
]


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
_FIELD_KEYS = ("address", "type", "mask", "range")
_SHA1 = re.compile(r"^[0-9a-fA-F]{40}$")


def data_error(source: Path | str, expected: str, found: str, fix: str, hint: str = "") -> DataFileError:
    """Return the error for a data file that does not say what it should.

    Args:
        source: The data file.
        expected: What the file should hold there.
        found: What it holds instead.
        fix: How to fix it, as the end of "To fix it, ...".
        hint: Text added at the end, e.g. a did-you-mean suggestion.
    """
    return DataFileError(f"{source}: expected {expected}; found {found}. To fix it, {fix}.{hint}")


def _describe(value: Any) -> str:
    text = repr(value)
    return f"{type(value).__name__} {text if len(text) <= 60 else text[:57] + '...'}"


def _expect(source: Path, where: str, value: Any, kind: type | tuple[type, ...], what: str) -> Any:
    if isinstance(value, kind) and not (isinstance(value, bool) and kind is not bool):
        return value
    raise data_error(source, f"{where} to be {what}", _describe(value), f"write {where} as {what}")


def _check_keys(source: Path, where: str, mapping: Mapping[str, Any], allowed: tuple[str, ...]) -> None:
    for key in mapping:
        if key not in allowed:
            raise data_error(
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
    from retrokit.host.fields import FieldSpec

    where = f"field {name!r}"
    entry = _expect(source, where, entry, Mapping, "a mapping with address, type and optionally mask and range")
    _check_keys(source, where, entry, _FIELD_KEYS)
    for key in ("address", "type"):
        if key not in entry:
            raise data_error(source, f"{where} to have {key!r}", f"the keys {sorted(entry)}", f"add its {key}")
    address = _int(source, f"the address of {where}", entry["address"])
    code = _expect(source, f"the type of {where}", entry["type"], str, "a type code string such as '>u2'")
    mask = None if entry.get("mask") is None else _int(source, f"the mask of {where}", entry["mask"])
    if address < 0:  # masks may be negative: Gym Retro's are two's complement (Amidar-Atari2600)
        raise data_error(source, f"{where} to have a non-negative address", repr(entry), "fix the address")
    if address >= 1 << 64:
        raise data_error(source, f"{where} to have an address below 2**64", f"{address:#x}", "fix the address")
    if mask is not None:
        if not -(1 << 63) <= mask < 1 << 64:
            raise data_error(
                source, f"the mask of {where} to fit in 64 bits (the widest field is 8 bytes)", f"{mask:#x}",
                "fix the mask",
            )
        if mask >= 1 << 63:  # the same 64 bits as a signed number, as fields are decoded
            mask -= 1 << 64
    bounds = _range(source, where, entry.get("range"))
    try:
        return FieldSpec(name, address, code, mask, bounds)
    except FieldTypeError as exc:  # the type code; FieldSpec parses it
        raise FieldTypeError(f"{source}: {where}: {exc}") from exc
    except InvalidArgumentError as exc:  # the range: FieldSpec checks it against the type
        raise data_error(source, f"the range of {where} to fit it", str(exc), "fix the range") from exc


def _range(source: Path, where: str, value: Any) -> tuple[int, int] | None:
    """A field's ``range: [lo, hi]``: the values it takes in play (None when not given)."""
    if value is None:
        return None
    pair = _expect(source, f"the range of {where}", value, list, "a list [lo, hi]")
    if len(pair) != 2:
        raise data_error(source, f"the range of {where} to be [lo, hi]", _describe(value), "write two numbers")
    return _int(source, f"the range of {where}", pair[0]), _int(source, f"the range of {where}", pair[1])


def _fields(source: Path, where: str, value: Any) -> Mapping[str, FieldSpec]:
    value = _expect(source, where, value if value is not None else {}, Mapping, "a mapping of field names")
    return MappingProxyType({str(name): _field(source, str(name), entry) for name, entry in value.items()})


def _sha1(source: Path, where: str, value: Any) -> str:
    if not isinstance(value, str) or not _SHA1.match(value.strip()):
        raise data_error(source, f"{where} to be a SHA-1 of 40 hex digits", _describe(value), "fix the hash")
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

    from retrokit.data.yamlfile import DuplicateKeyError, load_yaml, read_yaml_text

    source = Path(path)
    try:
        doc = load_yaml(read_yaml_text(source, "a game.yaml data file"))
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or exc
        if isinstance(exc, DuplicateKeyError):
            raise data_error(source, "each key once in a mapping", f"{problem}{at}", "remove or rename one") from exc
        raise data_error(source, "valid YAML", f"a syntax error{at}: {problem}", "fix the YAML syntax") from exc
    except FileSystemError:
        raise
    except (OSError, UnicodeDecodeError) as exc:
        raise data_error(source, "a readable UTF-8 file", str(exc), "check the file") from exc
    doc = _expect(source, "the file", doc, dict, "a mapping (system, roms, fields, states, players)")
    extra = {k: v for k, v in doc.items() if k not in _YAML_KEYS}
    roms_list = _expect(source, "'roms'", doc.get("roms", []), list, "a list of {sha1: ..., label: ...}")
    sha1s = tuple(
        _sha1(source, "each rom", r.get("sha1") if isinstance(r, Mapping) else r) for r in roms_list
    )
    states = _expect(source, "'states'", doc.get("states") or {}, Mapping, "a mapping with default, list, by_players")
    _check_keys(source, "'states'", states, ("default", "list", "by_players"))
    default = states.get("default")
    players = _expect(source, "'players'", doc.get("players", 1), int, "a positive integer")
    system = doc.get("system")
    fields = _fields(source, "'fields'", doc.get("fields"))
    players = _positive(source, players)
    # The shipped JSON Schema is the one list of the keys game.yaml may hold, so a
    # typo such as 'intgrate:' is an error (with its line and a did-you-mean),
    # never silently ignored. The values are checked where they are read, in
    # the words of each part (recipes: retrokit.data.integrate); `retrokit
    # validate` reports every schema issue.
    from retrokit.data.schema import check_file, raise_first

    raise_first([issue for issue in check_file(source, "game") if issue.unknown_key])
    return GameInfo(
        source=source,
        system=None if system is None else _expect(source, "'system'", system, str, "a system name"),
        sha1s=sha1s,
        fields=fields,
        default_state=None if default is None else _expect(source, "the default state", default, str, "a name"),
        states=None if states.get("list") is None else _names(source, "the state list", states["list"]),
        players=players,
        default_player_states=_names(source, "'states: by_players'", states.get("by_players", [])),
        title=doc.get("title"),
        extra=MappingProxyType(extra),
    )


def _positive(source: Path, players: int) -> int:
    if players < 1:
        raise data_error(source, "'players' to be at least 1", str(players), "fix the player count")
    return players


#: The largest Gym Retro data file read (data.json, metadata.json, rom.sha): the wheel's are a few kilobytes.
MAX_JSON_BYTES = 4 * 2**20


def _read_json(path: Path, required: bool) -> dict[str, Any]:
    if not os.path.lexists(path) and not required:
        return {}
    try:
        # Duplicate keys are kept as json keeps them (the last wins): the wheel's own data files have some.
        doc = json.loads(read_regular_file(path, f"a Gym Retro {path.name}", MAX_JSON_BYTES).decode("utf-8"))
    except json.JSONDecodeError as exc:
        raise data_error(
            path, "valid JSON", f"a syntax error at line {exc.lineno}, column {exc.colno}: {exc.msg}",
            "fix the JSON syntax",
        ) from exc
    except RecursionError:
        raise data_error(path, "JSON nested at most a few hundred deep", "deeper nesting", "fix the file") from None
    except UnicodeDecodeError as exc:
        raise data_error(path, "a readable UTF-8 JSON file", str(exc), "check the file") from exc
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
    if os.path.lexists(sha_path):
        text = read_regular_file(sha_path, "a Gym Retro rom.sha", MAX_JSON_BYTES).decode("utf-8", errors="replace")
        lines = [line.strip() for line in text.splitlines()]
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
    if os.path.lexists(folder / "game.yaml"):  # a FIFO, a folder or a loop there is an error, not Gym Retro's files
        return read_game_yaml(folder / "game.yaml")
    return read_gym_retro_folder(folder)
