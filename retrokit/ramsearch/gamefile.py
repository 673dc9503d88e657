"""Writing a found variable into a game.yaml, keeping the file as its author wrote it.

A round-trip YAML library keeps comments, but not the alignment of columns
nor the indentation of lists, so the file is edited as text: ruamel.yaml
parses it and tells on which line each field starts; the new field's line is
written in the style of its neighbours (flow mapping, column of the values,
hex addresses) and inserted after the last field, or in place of the field it
replaces. Every other byte stays as it was. The result is parsed again and
checked to hold exactly the old data plus the new field before it is written,
through a temporary file renamed into place.
"""

from __future__ import annotations

import io
import os
import re
from pathlib import Path
from typing import Any

from retrokit.errors import DataFileError, FileConflictError, InvalidArgumentError
from retrokit.paths import atomic_write

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
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


def field_line(indent: str, name: str, address: str, type_code: str, pad_to: int = 0) -> str:
    """One field as a flow-mapping line, its value starting at column ``pad_to`` if the name leaves room."""
    key = f"{indent}{name}:"
    return f'{key.ljust(max(pad_to, len(key) + 1))}{{address: {address}, type: "{type_code}"}}'


def add_field(path: str | os.PathLike[str], name: str, address: str, type_code: str, *, force: bool = False) -> bool:
    """Write a field ``name: {address: ..., type: "..."}`` into a game.yaml.

    Args:
        path: The game.yaml.
        name: The field's name (letters, digits and underscores, not starting with a digit).
        address: The console address as it is to be written, e.g. ``"0xFF002B"``.
        type_code: The type code, e.g. ``"|u1"``.
        force: Replace a field of the same name.

    Returns:
        Whether a field of that name was replaced.

    Raises:
        InvalidArgumentError: ``name`` is not a valid field name.
        FileConflictError: The file has a field of that name and ``force`` is false.
        DataFileError: The file is missing, is not YAML, or its ``fields`` is not a mapping.
    """
    path = Path(path)
    if not _NAME.match(name):
        raise InvalidArgumentError(
            f"Expected a field name of letters, digits and underscores not starting with a digit, got {name!r}. "
            "Scenarios use field names as variables."
        )
    try:
        text = path.read_bytes().decode("utf-8")  # as it is: read_text would turn \r\n into \n
    except UnicodeDecodeError as exc:
        raise DataFileError(f"{path}: expected a UTF-8 text file; found {exc.reason} at byte {exc.start}.") from None
    except OSError as exc:
        raise DataFileError(f"Expected a game.yaml at {str(path)!r}; found an error: {exc.strerror or exc}.") from None
    doc = _load(text, path)
    if doc is None:
        doc, text = {}, ""
    if not isinstance(doc, dict):
        raise DataFileError(
            f"{path}: expected a mapping at the top of the file; found {type(doc).__name__}. Fix the file first."
        )
    fields = doc.get("fields")
    if fields is not None and not isinstance(fields, dict):
        raise DataFileError(
            f"{path}: expected 'fields' to be a mapping; found {type(fields).__name__}. Fix the file first."
        )
    replaced = bool(fields) and name in fields
    if replaced and not force:
        line = text.splitlines()[fields.lc.key(name)[0]].strip()
        raise FileConflictError(
            f"Expected no field {name!r} in {path}; found one ({line}). "
            "Choose another name, or pass --force (force=True) to replace it."
        )
    new_text = _insert(text, doc, fields, name, address, type_code)
    _check(path, text, new_text, name, address, type_code)
    atomic_write(path, new_text.encode("utf-8"), overwrite=True)
    return replaced


def _insert(text: str, doc: Any, fields: Any, name: str, address: str, type_code: str) -> str:
    lines = text.splitlines(keepends=True)
    nl = "\r\n" if lines and lines[0].endswith("\r\n") else "\n"  # the file's own line ends
    if lines and not lines[-1].endswith("\n"):
        lines[-1] += nl
    if not fields:  # no fields yet: a new block at the end, or in place of an empty 'fields:'
        entry = field_line("  ", name, address, type_code) + nl
        if "fields" in doc:
            line = doc.lc.key("fields")[0]
            comment = lines[line].partition("#")[2]
            lines[line] = "fields:" + (f"  #{comment}" if comment else nl)
            lines.insert(line + 1, entry)
        else:
            lines.append("fields:" + nl + entry)
        return "".join(lines)
    if getattr(fields, "fa", None) is not None and fields.fa.flow_style():
        return _dump_round_trip(doc, fields, name, address, type_code)
    names = list(fields)
    column = fields.lc.key(names[-1])[1]
    indent = " " * column
    columns = [c for c in (_value_column(lines[fields.lc.key(k)[0]]) for k in names) if c]
    pad = max(set(columns), key=columns.count) if columns else 0  # the column most values start at
    entry = field_line(indent, name, address, type_code, pad)
    if name in fields:
        first = fields.lc.key(name)[0]
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


def _dump_round_trip(doc: Any, fields: Any, name: str, address: str, type_code: str) -> str:
    """A file whose fields are one flow mapping: let ruamel.yaml write it (comments kept, alignment not)."""
    from ruamel.yaml.comments import CommentedMap
    from ruamel.yaml.scalarint import HexCapsInt
    from ruamel.yaml.scalarstring import DoubleQuotedScalarString

    value = HexCapsInt(int(address, 0), width=len(address) - 2) if address.lower().startswith("0x") else int(address)
    entry = CommentedMap(address=value, type=DoubleQuotedScalarString(type_code))
    entry.fa.set_flow_style()
    fields[name] = entry
    out = io.StringIO()
    _yaml().dump(doc, out)
    return out.getvalue()


def _check(path: Path, old_text: str, new_text: str, name: str, address: str, type_code: str) -> None:
    """Parse the edited text and check it holds the old data plus (or with) the new field, nothing else."""
    expected = _plain(_load(old_text, path)) or {}
    expected.setdefault("fields", {})
    if expected["fields"] is None:
        expected["fields"] = {}
    expected["fields"][name] = {"address": int(address, 0), "type": type_code}
    found = _plain(_load(new_text, path))
    if found != expected:
        raise DataFileError(
            f"{path}: expected to add field {name!r} by inserting one line; the file's layout defeated it "
            "(the edit would change other data). Add the line by hand: "
            + field_line("  ", name, address, type_code).strip()
        )
