"""Writing a found variable into a game.yaml, keeping the file as its author wrote it.

A round-trip YAML library keeps comments, but not the alignment of columns
nor the indentation of lists, so the file is edited as text: ruamel.yaml
parses it and tells on which line each field starts; the new field's line is
written in the style of its neighbours (flow mapping, column of the values,
hex addresses) and inserted after the last field, or in place of the field it
replaces. Every other byte stays as it was. The result is parsed again and
checked to hold exactly the old data plus the new field before it is written,
through a temporary file renamed into place, all under the folder's lock
(:func:`retrokit.paths.locked`), so edits made at once by several commands
and studios are each kept. A game.yaml that is a symlink is
written through to the file it names, so the link stays and its target is
the file updated.
"""

from __future__ import annotations

import io
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from retrokit.errors import DataFileError, FileConflictError, FileSystemError, InvalidArgumentError, shown
from retrokit.host.typecodes import FieldType
from retrokit.paths import atomic_write, locked, require_regular_file

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
MAX_NAME = 64  # a field name is a scenario's variable: longer is a mistake (and YAML keys stop at 1024)
MAX_FILE = 16 << 20  # a game.yaml of a few thousand fields takes a few hundred KiB
_FLOW_VALUE = re.compile(r"^(\s*)([^:#]+?):(\s*)(\{[^}]*\})(.*)$")


def _yaml():
    from ruamel.yaml import YAML

    yaml = YAML(typ="rt")
    yaml.preserve_quotes = True
    return yaml


def _load(text: str, path: Path) -> Any:
    from ruamel.yaml import YAMLError

    try:
        return _yaml().load(text)
    except YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = f" at line {mark.line + 1}" if mark is not None else ""
        raise DataFileError(f"{path}: expected valid YAML; found a syntax error{at}. Fix the file first.") from None


def _plain(node: Any) -> Any:
    """The data of a round-trip node, as plain dicts, lists and scalars."""
    if isinstance(node, dict):
        return {str(k): _plain(v) for k, v in node.items()}
    if isinstance(node, list):
        return [_plain(v) for v in node]
    if isinstance(node, bool) or node is None:
        return node
    if isinstance(node, int):
        return int(node)
    if isinstance(node, float):
        return float(node)
    return str(node)


def check_field_name(name: object) -> str:
    """Return ``name`` if it can be a field's name (a scenario's variable); raise otherwise.

    Raises:
        InvalidArgumentError: ``name`` is not letters, digits and underscores, starts with a digit, or is too long.
    """
    if not isinstance(name, str) or not _NAME.match(name) or len(name) > MAX_NAME:
        raise InvalidArgumentError(
            f"Expected a field name of at most {MAX_NAME} letters, digits and underscores, not starting with a "
            f"digit; got {shown(name)}. Scenarios use field names as variables."
        )
    return name


def check_range(value_range: object, ftype: FieldType) -> tuple[int, int]:
    """Return ``value_range`` as ``(lo, hi)`` if it is two whole numbers ``lo <= hi`` that ``ftype`` can hold.

    Raises:
        InvalidArgumentError: It is not.
    """
    low, high = ftype.value_range()
    ok = (
        isinstance(value_range, (tuple, list))
        and len(value_range) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) for v in value_range)
    )
    if not ok or not low <= value_range[0] <= value_range[1] <= high:
        raise InvalidArgumentError(
            f"Expected a range LO HI of whole numbers with {low} <= LO <= HI <= {high} (what {ftype.code} holds); "
            f"got {shown(value_range)}."
        )
    return int(value_range[0]), int(value_range[1])


def field_line(
    indent: str, name: str, address: str, type_code: str, pad_to: int = 0, value_range: tuple[int, int] | None = None,
    mask: int | None = None,
) -> str:
    """One field as a flow-mapping line, its value starting at column ``pad_to`` if the name leaves room."""
    key = f"{indent}{name}:"
    extra = "" if mask is None else f", mask: 0x{mask:02X}"
    extra += "" if value_range is None else f", range: [{value_range[0]}, {value_range[1]}]"
    return f'{key.ljust(max(pad_to, len(key) + 1))}{{address: {address}, type: "{type_code}"{extra}}}'


def add_field(
    path: str | os.PathLike[str],
    name: str,
    address: str,
    type_code: str,
    *,
    force: bool = False,
    value_range: tuple[int, int] | None = None,
    mask: int | None = None,
) -> bool:
    """Write a field ``name: {address: ..., type: "..."}`` into a game.yaml.

    Args:
        path: The game.yaml.
        name: The field's name (letters, digits and underscores, not starting with a digit).
        address: The console address as it is to be written, e.g. ``"0xFF002B"``.
        type_code: The type code, e.g. ``"|u1"``.
        force: Replace a field of the same name.
        value_range: The values the field may hold, ``(lo, hi)``, written as ``range: [lo, hi]``.
        mask: The bits kept of the value (a flag held in one bit), written as ``mask: 0x04``.

    Returns:
        Whether a field of that name was replaced.

    Raises:
        InvalidArgumentError: ``name`` is not a valid field name.
        FileConflictError: The file has a field of that name and ``force`` is false.
        DataFileError: The file is missing, is not YAML, or its ``fields`` is not a mapping.
    """
    check_field_name(name)
    with locked(path):  # read, edit and write as one step: a writer beside us would lose this field, or we its
        return _add_field(path, name, address, type_code, force, value_range, mask)


def _add_field(
    path: str | os.PathLike[str], name: str, address: str, type_code: str, force: bool,
    value_range: tuple[int, int] | None, mask: int | None,
) -> bool:
    path, text, doc, fields = _open_section(path, "fields")
    replaced = bool(fields) and name in fields
    if replaced and not force:
        line = text.splitlines()[fields.lc.key(name)[0]].strip()
        raise FileConflictError(
            f"Expected no field {name!r} in {path}; found one ({line}). "
            "Choose another name, or pass --force (force=True) to replace it."
        )
    entry = _Entry(name, address, type_code, value_range, mask)
    before = _plain(doc)  # the data as read, taken before _insert may edit the document (parsing again costs ~0.1 s)
    new_text = _insert(text, doc, fields, entry)
    _check(path, before, new_text, entry)
    atomic_write(path, new_text.encode("utf-8"), overwrite=True)
    return replaced


@dataclass(frozen=True)
class _Entry:
    """The field being written."""

    name: str
    address: str
    type_code: str
    value_range: tuple[int, int] | None = None
    mask: int | None = None

    def line(self, indent: str, pad_to: int = 0) -> str:
        return field_line(indent, self.name, self.address, self.type_code, pad_to, self.value_range, self.mask)

    def data(self) -> dict[str, Any]:
        """The field as the file's data holds it."""
        out: dict[str, Any] = {"address": int(self.address, 0), "type": self.type_code}
        if self.mask is not None:
            out["mask"] = self.mask
        if self.value_range is not None:
            out["range"] = list(self.value_range)
        return out


def _open_section(path: str | os.PathLike[str], key: str) -> tuple[Path, str, Any, Any]:
    """Read a game.yaml for a one-line edit of its ``key`` mapping: the path, text, document and that mapping.

    Raises:
        DataFileError: The file is missing or not YAML, or its top or its ``key`` is not a mapping.
    """
    path, text = _read(path)
    doc = _load(text, path)
    if doc is None:
        doc, text = {}, ""
    if not isinstance(doc, dict):
        raise DataFileError(
            f"{path}: expected a mapping at the top of the file; found {type(doc).__name__}. Fix the file first."
        )
    section = doc.get(key)
    if section is not None and not isinstance(section, dict):
        raise DataFileError(
            f"{path}: expected {key!r} to be a mapping; found {type(section).__name__}. Fix the file first."
        )
    return path, text, doc, section


def _read(path: str | os.PathLike[str]) -> tuple[Path, str]:
    """The game.yaml a path names (a symlink's target, written through it) and its text.

    Raises:
        DataFileError: It is missing, not a regular file, too big, or not UTF-8.
    """
    path = Path(path)
    try:
        # Written through a symlink to its target: replacing the link with a copy would leave the real file as it was.
        path = require_regular_file(path, "a game.yaml").resolve()
        if path.stat().st_size > MAX_FILE:
            raise DataFileError(f"{path}: expected a game.yaml of at most {MAX_FILE >> 20} MiB; found a bigger file.")
        return path, path.read_bytes().decode("utf-8")  # as it is: read_text would turn \r\n into \n
    except FileSystemError as exc:
        raise DataFileError(str(exc)) from None
    except UnicodeDecodeError as exc:
        raise DataFileError(f"{path}: expected a UTF-8 text file; found {exc.reason} at byte {exc.start}.") from None
    except OSError as exc:
        raise DataFileError(f"Expected a game.yaml at {str(path)!r}; found an error: {exc.strerror or exc}.") from None


_PLAIN_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.-]*$")


def set_default_state(path: str | os.PathLike[str], name: str) -> None:
    """Write ``states: default: NAME`` into a game.yaml, keeping every other byte as it was.

    Raises:
        DataFileError: The file is missing or not YAML, its ``states`` is not a mapping, or its
            layout defeats a one-line edit.
    """
    with locked(path):  # as add_field: the whole read-modify-write under the folder's lock
        _set_default_state(path, name)


def _set_default_state(path: str | os.PathLike[str], name: str) -> None:
    path, text, doc, states = _open_section(path, "states")
    value = _scalar(name)
    lines = text.splitlines(keepends=True)
    nl = "\r\n" if lines and lines[0].endswith("\r\n") else "\n"
    if lines and not lines[-1].endswith("\n"):
        lines[-1] += nl
    wanted = dict(_plain(states) or {})
    wanted["default"] = name
    if isinstance(wanted.get("by_players"), list) and wanted["by_players"]:
        wanted["by_players"][0] = name  # the 1-player default comes before `default`: it names the new state too
    if "states" not in doc:
        lines.append(f"states:{nl}  default: {value}{nl}")
    elif not states or states.fa.flow_style():
        line = doc.lc.key("states")[0]
        if _entry_end(lines, line, 0) != line:
            raise DataFileError(
                f"{path}: expected 'states' on one line; found it spread over several. Fix the file first."
            )
        inner = ", ".join(f"{k}: {_flow(v)}" for k, v in wanted.items())
        lines[line] = f"states: {{{inner}}}{_trailing_comment_of(lines[line])}{nl}"
    else:  # a block mapping: edit its lines in place (by_players first: inserting `default` moves the lines after it)
        for key in ("by_players", "default"):
            if key not in states:
                continue
            line, column = states.lc.key(key)
            if _entry_end(lines, line, column) != line:
                raise DataFileError(f"{path}: expected 'states: {key}:' on one line; found it spread over several.")
            lines[line] = f"{' ' * column}{key}: {_flow(wanted[key])}{_trailing_comment_of(lines[line])}{nl}"
        if "default" not in states:
            line, column = states.lc.key(next(iter(states)))
            lines.insert(line, f"{' ' * column}default: {value}{nl}")
    new_text = "".join(lines)
    expected = _plain(doc) or {}  # the data as read: nothing above edits the document
    expected["states"] = wanted
    _verify(path, new_text, expected, f"states: default: {value}")
    atomic_write(path, new_text.encode("utf-8"), overwrite=True)


def _scalar(name: str) -> str:
    """A state name as a YAML scalar: plain when it can be, else double-quoted (JSON strings are YAML's)."""
    return name if _PLAIN_NAME.match(name) else json.dumps(name)


def _flow(value: Any) -> str:
    """A plain value (a name, or a list of them) in YAML flow style."""
    if isinstance(value, list):
        return "[" + ", ".join(_flow(v) for v in value) + "]"
    return _scalar(value) if isinstance(value, str) else json.dumps(value)


def _trailing_comment_of(line: str) -> str:
    """A line's trailing ``# comment`` (with the spaces before it), if it has one outside quotes."""
    body = line.rstrip("\r\n")
    match = re.search(r"\s+#[^'\"]*$", body)
    return match.group() if match else ""


def _verify(path: Path, new_text: str, expected: Any, line: str) -> None:
    if _plain(_load(new_text, path)) != expected:
        raise DataFileError(
            f"{path}: expected to edit one line; the file's layout defeated it (the edit would change other "
            f"data). Add the line by hand: {line}"
        )


def _insert(text: str, doc: Any, fields: Any, new: _Entry) -> str:
    lines = text.splitlines(keepends=True)
    nl = "\r\n" if lines and lines[0].endswith("\r\n") else "\n"  # the file's own line ends
    if lines and not lines[-1].endswith("\n"):
        lines[-1] += nl
    if not fields:  # no fields yet: a new block at the end, or in place of an empty 'fields:'
        entry = new.line("  ") + nl
        if "fields" in doc:
            line = doc.lc.key("fields")[0]
            comment = lines[line].partition("#")[2]
            lines[line] = "fields:" + (f"  #{comment}" if comment else nl)
            lines.insert(line + 1, entry)
        else:
            lines.append("fields:" + nl + entry)
        return "".join(lines)
    if getattr(fields, "fa", None) is not None and fields.fa.flow_style():
        return _dump_round_trip(doc, fields, new)
    names = list(fields)
    column = fields.lc.key(names[-1])[1]
    indent = " " * column
    columns = [c for c in (_value_column(lines[fields.lc.key(k)[0]]) for k in names) if c]
    pad = max(set(columns), key=columns.count) if columns else 0  # the column most values start at
    entry = new.line(indent, pad)
    if new.name in fields:
        first = fields.lc.key(new.name)[0]
        last = _entry_end(lines, first, column)
        comment = _trailing_comment(lines[first]) if first == last else ""
        lines[first : last + 1] = [entry + comment + nl]
    else:
        last = _entry_end(lines, fields.lc.key(names[-1])[0], column)
        lines.insert(last + 1, entry + nl)
    return "".join(lines)


def _value_column(line: str) -> int:
    """The column a one-line flow entry's value starts at (0 if the line is not one)."""
    match = _FLOW_VALUE.match(line.rstrip("\r\n"))
    return match.start(4) if match else 0


def _trailing_comment(line: str) -> str:
    match = _FLOW_VALUE.match(line.rstrip("\r\n"))
    rest = match.group(5) if match else ""
    return rest if rest.strip().startswith("#") else ""


def _entry_end(lines: list[str], first: int, column: int) -> int:
    """The last line of the entry whose key is on line ``first`` (its nested lines are indented deeper)."""
    last = first
    for index in range(first + 1, len(lines)):
        stripped = lines[index].strip()
        if not stripped or stripped.startswith("#"):
            continue
        if len(lines[index]) - len(lines[index].lstrip()) <= column:
            break
        last = index
    return last


def _dump_round_trip(doc: Any, fields: Any, new: _Entry) -> str:
    """A file whose fields are one flow mapping: let ruamel.yaml write it (comments kept, alignment not)."""
    from ruamel.yaml.comments import CommentedMap, CommentedSeq
    from ruamel.yaml.scalarint import HexCapsInt
    from ruamel.yaml.scalarstring import DoubleQuotedScalarString

    address = new.address
    value = HexCapsInt(int(address, 0), width=len(address) - 2) if address.lower().startswith("0x") else int(address)
    entry = CommentedMap(address=value, type=DoubleQuotedScalarString(new.type_code))
    if new.value_range is not None:
        entry["range"] = CommentedSeq(new.value_range)
        entry["range"].fa.set_flow_style()
    entry.fa.set_flow_style()
    fields[new.name] = entry
    out = io.StringIO()
    _yaml().dump(doc, out)
    return out.getvalue()


def _check(path: Path, before: Any, new_text: str, new: _Entry) -> None:
    """Parse the edited text; check it holds the data ``before`` the edit plus (or with) the new field, nothing else."""
    expected = before or {}
    expected.setdefault("fields", {})
    if expected["fields"] is None:
        expected["fields"] = {}
    expected["fields"][new.name] = new.data()
    _verify(path, new_text, expected, new.line("").strip())
