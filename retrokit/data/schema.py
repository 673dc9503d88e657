"""Checking YAML data files against the JSON Schemas shipped in ``retrokit/data/schemas/``.

The schemas describe ``game.yaml`` (``game.schema.json``), scenario files
(``scenario.schema.json``) and the files scenarios include
(``scenario-include.schema.json``). Editors with a YAML language server
complete and check files against them, e.g. with a first line::

    # yaml-language-server: $schema=<site-packages>/retrokit/data/schemas/game.schema.json

Here each problem is reported with the file, line and column where it is,
and unknown keys get a did-you-mean: the YAML is composed into nodes, which
keep their positions, before it is validated.
"""

from __future__ import annotations

import functools
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from retrokit.data.textmemo import TextMemo
from retrokit.data.yamlfile import compose_yaml, read_yaml_text
from retrokit.errors import DataFileError, FileSystemError, did_you_mean

__all__ = ["SCHEMAS", "SCHEMA_DIR", "SchemaIssue", "check_file", "check_text", "schema_path"]

SCHEMA_DIR = Path(__file__).with_name("schemas")
#: The kinds of data file, and their schema's file name.
SCHEMAS = {"game": "game.schema.json", "scenario": "scenario.schema.json", "include": "scenario-include.schema.json"}


@dataclass(frozen=True)
class SchemaIssue:
    """One place where a file breaks its schema.

    Attributes:
        file: The file.
        line: 1-based line.
        column: 1-based column.
        message: What is wrong there and how to fix it.
        keyword: The JSON Schema keyword it breaks, e.g. ``"additionalProperties"`` for an unknown key.
    """

    file: str
    line: int
    column: int
    message: str
    keyword: str = ""

    @property
    def unknown_key(self) -> bool:
        """Whether the issue is a key the schema does not know (often a typo)."""
        return self.keyword == "additionalProperties"

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}: {self.message}"


def schema_path(kind: str) -> Path:
    """Return the schema file of a kind of data file: ``"game"``, ``"scenario"`` or ``"include"``."""
    return SCHEMA_DIR / SCHEMAS[kind]


@functools.cache
def _validator(kind: str) -> Any:  # a jsonschema validator
    import jsonschema
    from referencing import Registry, Resource

    schemas = {name: json.loads((SCHEMA_DIR / name).read_text(encoding="utf-8")) for name in SCHEMAS.values()}
    registry = Registry().with_resources(
        (uri, Resource.from_contents(doc)) for name, doc in schemas.items() for uri in (doc["$id"], name)
    )
    schema = schemas[SCHEMAS[kind]]
    return jsonschema.Draft202012Validator(schema, registry=registry)


def warm() -> None:
    """Build every kind's validator now, once for every process forked from this one (an evaluation's fork server)."""
    for kind in SCHEMAS:
        _validator(kind)


def check_file(path: str | os.PathLike[str], kind: str) -> list[SchemaIssue]:
    """Return every problem of a YAML data file against its kind's schema (empty: it conforms)."""
    path = Path(path)
    try:
        text = read_yaml_text(path, f"a YAML {kind} file")
    except FileSystemError as exc:
        return [SchemaIssue(str(path), 1, 1, str(exc))]
    except UnicodeDecodeError as exc:
        return [SchemaIssue(str(path), 1, 1, f"expected a readable UTF-8 file; found an error: {exc}")]
    return check_text(text, kind, str(path))


def check_text(text: str, kind: str, name: str = "<text>") -> list[SchemaIssue]:
    """Return every problem of YAML ``text`` against the schema of ``kind``; ``name`` labels it."""
    # Every make() reads its game.yaml again (an edit must show): a text checked before is known by its digest.
    return list(_CHECKED.get(text, (kind, name), lambda: tuple(_check(text, kind, name))))


_CHECKED: TextMemo[tuple[SchemaIssue, ...]] = TextMemo()
""":func:`check_text`'s answers by the text, its kind and its name."""


def _check(text: str, kind: str, name: str) -> list[SchemaIssue]:
    try:
        root = compose_yaml(text)  # counted with aliases expanded: the checks below walk every value
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line, column = (mark.line + 1, mark.column + 1) if mark is not None else (1, 1)
        problem = getattr(exc, "problem", None) or exc
        return [SchemaIssue(name, line, column, f"expected valid YAML; found a syntax error: {problem}")]
    if root is None:
        root = yaml.MappingNode("tag:yaml.org,2002:map", [])
    try:
        document = _plain(root)
    except (yaml.YAMLError, ValueError, TypeError) as exc:
        return [SchemaIssue(name, root.start_mark.line + 1, root.start_mark.column + 1, f"expected plain data: {exc}")]
    issues = []
    errors = sorted(_validator(kind).iter_errors(document), key=lambda e: list(map(str, e.absolute_path)))
    for error in errors:
        node, message = _locate(root, error)
        issues.append(SchemaIssue(name, node.start_mark.line + 1, node.start_mark.column + 1, message, error.validator))
    return sorted(issues, key=lambda i: (i.line, i.column))


def raise_first(issues: list[SchemaIssue]) -> None:
    """Raise the first issue as a :class:`DataFileError` (nothing if there are none)."""
    if issues:
        # An unknown key is often the cause of a missing one ('untill:'), so it goes first.
        issues = sorted(issues, key=lambda i: not i.unknown_key)
        more = f" ({len(issues) - 1} more problem{'s' * (len(issues) > 2)} in the file)" if len(issues) > 1 else ""
        raise DataFileError(f"{issues[0]}{more}")


def _plain(node: yaml.Node) -> Any:
    """The JSON-like value of a node: mapping keys become strings, as JSON's are."""
    if isinstance(node, yaml.MappingNode):
        return {str(_plain(k)): _plain(v) for k, v in node.value}
    if isinstance(node, yaml.SequenceNode):
        return [_plain(v) for v in node.value]
    return _scalar(node)


def _scalar(node: yaml.ScalarNode) -> Any:
    value = yaml.constructor.SafeConstructor().construct_object(node, deep=True)
    if not isinstance(value, (str, int, float, bool, type(None))):
        return str(value)  # dates and the like: the schema sees text
    return value


def _child(node: yaml.Node, part: str | int) -> tuple[yaml.Node | None, yaml.Node | None]:
    """The (key node, value node) of ``part`` inside ``node``."""
    if isinstance(node, yaml.MappingNode):
        for key, value in node.value:
            if isinstance(key, yaml.ScalarNode) and key.value == str(part):
                return key, value
    if isinstance(node, yaml.SequenceNode) and isinstance(part, int) and part < len(node.value):
        return None, node.value[part]
    return None, None


def _where(path: list[str | int]) -> str:
    if not path:
        return "the file"
    return "'" + ".".join(str(p) if not isinstance(p, int) else f"[{p}]" for p in path).replace(".[", "[") + "'"


def _locate(root: yaml.Node, error: Any) -> tuple[yaml.Node, str]:  # a jsonschema ValidationError
    """The node an error is about, and a message in retrokit's style."""
    path = list(error.absolute_path)
    node = root
    for part in path:
        _, value = _child(node, part)
        if value is None:
            break
        node = value
    where = _where(path)
    if error.validator == "additionalProperties" and isinstance(node, yaml.MappingNode):
        allowed = list(error.schema.get("properties", {}))
        patterns = list(error.schema.get("patternProperties", {}))
        unknown = [k for k in error.instance if k not in allowed and not any(re.match(p, k) for p in patterns)]
        key_node, _ = _child(node, unknown[0]) if unknown else (None, None)
        hint = did_you_mean(unknown[0], allowed) if unknown else ""
        return key_node or node, (
            f"unknown key {unknown[0] if unknown else '?'!r} in {where}; expected one of: "
            f"{', '.join(allowed)}{' (or x-anything, for other tools)' if patterns else ''}.{hint} Rename or remove it."
        )
    if error.validator == "required":
        missing = error.message.split(" is a required")[0]
        keys = ", ".join(map(str, error.instance)) if isinstance(error.instance, dict) else ""
        return node, f"expected {missing} in {where}; found {('the keys ' + keys) if keys else 'no keys'}. Add it."
    if error.validator == "not" and path == []:
        return node, "give either 'reward' (one player) or 'rewards' (a list, one per player), not both."
    description = error.schema.get("description", "") if isinstance(error.schema, dict) else ""
    found = repr(error.instance)
    found = found if len(found) <= 60 else found[:57] + "..."
    expected = _expected(error)
    return node, f"{where}: expected {expected}; found {found}." + (f" ({description})" if description else "")


def _expected(error: Any) -> str:
    schema = error.schema if isinstance(error.schema, dict) else {}
    kind = error.validator
    if kind == "type":
        types = schema.get("type")
        return " or ".join(types) if isinstance(types, list) else str(types)
    if kind == "pattern":
        return f"text matching {schema.get('pattern')}"
    if kind in ("minimum", "maximum", "minItems", "maxItems", "minProperties"):
        return f"{kind} {schema.get(kind)}"
    if kind == "oneOf":
        return "one of the allowed forms (" + "; ".join(
            str(s.get("type", s.get("$ref", "?"))) for s in schema.get("oneOf", [])
        ) + ")"
    return error.message
