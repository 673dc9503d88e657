"""Read a retrokit scenario YAML file into a :class:`ScenarioSpec`.

The file is composed with PyYAML into nodes, not loaded into plain values, so
that each expression keeps the line and column it was written at; every error
in it points into the file. The format is documented in ``docs/scenarios.md``::

    name: contest
    include: [levels.yaml]        # more tables and definitions
    tables:
      level_end:
        by: [zone, act]
        values:
          0, 0: 0x2560
    define:
      progress: clip(x - initial(x), 0, end_x) / end_x
    reward: delta(progress, 0) * 9000
    done: lives < prev(lives) or progress >= 1
    # or, per player: rewards: [...], dones: [p1_lives == 0, p2_lives == 0]
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np
import yaml

from retrokit.data.yamlfile import MAX_VALUES, TooManyValuesError, iter_nodes
from retrokit.dsl.check import constant
from retrokit.dsl.parser import MAX_INT, parse
from retrokit.dsl.source import Snippet, SourceText, align, located, read_source
from retrokit.dsl.spec import Scalar, ScenarioSpec, Table
from retrokit.errors import RetrokitError, ScenarioError, did_you_mean, shown

TOP_KEYS = (
    "name", "description", "include", "tables", "define", "reward", "rewards", "done", "dones", "actions", "crop",
    "jump", "reset_ram",
)
INCLUDE_KEYS = ("description", "include", "tables", "define")
TABLE_KEYS = ("by", "default", "values", "description")

#: libyaml's composer (as retrokit/data/yamlfile.py uses) where PyYAML has it: the pure-Python one took ~45% of
#: loading a scenario. Its marks count characters as the Python one's do, so errors point at the same places.
_LOADER: type = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_INT_TAG = "tag:yaml.org,2002:int"
_FLOAT_TAG = "tag:yaml.org,2002:float"
#: The tags YAML gives plain values by itself; any other was written on purpose (``!!python/...``).
_PLAIN_TAGS = frozenset(
    f"tag:yaml.org,2002:{name}" for name in ("str", "int", "float", "bool", "null", "seq", "map", "timestamp", "merge")
)


class _Reader:
    """Turn the nodes of one YAML text into spec parts, with located errors."""

    def __init__(self, source: SourceText) -> None:
        self.source = source

    def error(self, node: yaml.Node, message: str) -> ScenarioError:
        return located(ScenarioError, self.source, node.start_mark.index, max(node.end_mark.index, node.start_mark.index + 1), message)

    def compose(self) -> yaml.MappingNode | None:
        try:
            root = yaml.compose(self.source.text, Loader=_LOADER)
        except yaml.MarkedYAMLError as exc:
            mark = exc.problem_mark or exc.context_mark
            index = mark.index if mark is not None else 0
            raise located(ScenarioError, self.source, index, index + 1, f"this is not valid YAML: {exc.problem or exc}") from None
        except yaml.reader.ReaderError as exc:  # a control character such as NUL
            raise located(
                ScenarioError, self.source, exc.position, exc.position + 1,
                f"expected printable text, got the control character {chr(exc.character)!r}; remove it",
            ) from None
        except (yaml.YAMLError, RecursionError) as exc:  # RecursionError: collections nested thousands deep
            raise located(ScenarioError, self.source, 0, 1, f"this is not valid YAML: {exc}") from None
        if root is not None and not isinstance(root, yaml.MappingNode):
            raise self.error(root, "a scenario file holds a mapping (key: value lines) at its top")
        if root is not None:
            self._check_tags(root)
        return root

    def _check_tags(self, root: yaml.Node) -> None:
        """Refuse explicit tags (``!!python/...``, ``!!binary``, ``!foo``): a scenario is plain YAML.

        Aliases are followed, so the walk also counts the values the file
        holds once they are expanded: a few lines of nested aliases can stand
        for billions, and reading them would never end.
        """
        try:
            for node in iter_nodes(root):
                if node.tag not in _PLAIN_TAGS:
                    raise self.error(node, f"expected plain YAML values, got one tagged {node.tag!r}; remove the tag")
        except TooManyValuesError:
            raise self.error(
                root, f"expected aliases (*name) to add at most {MAX_VALUES} YAML values to a scenario once "
                f"expanded, got more; write out what the aliases repeat, or drop them",
            ) from None

    def mapping(self, node: yaml.Node, what: str, allowed: tuple[str, ...] | None = None) -> dict[str, tuple[yaml.Node, yaml.Node]]:
        """The entries of a mapping node, checking for duplicate and unknown keys."""
        if not isinstance(node, yaml.MappingNode):
            raise self.error(node, f"{what} must be a mapping (key: value lines)")
        entries: dict[str, tuple[yaml.Node, yaml.Node]] = {}
        for key, value in node.value:
            if not isinstance(key, yaml.ScalarNode):
                raise self.error(key, f"the keys of {what} must be plain names or numbers")
            name = key.value
            if name in entries:
                line = entries[name][0].start_mark.line + 1
                raise self.error(key, f"{name!r} is given twice in {what} (first on line {line})")
            if allowed is not None and name not in allowed:
                raise self.error(key, f"unknown key {name!r} in {what}." + did_you_mean(name, allowed) + f" Known keys: {', '.join(allowed)}")
            entries[name] = (key, value)
        return entries

    def snippet(self, node: yaml.Node, role: str) -> Snippet:
        """An expression written as a YAML scalar, mapped character by character into the file."""
        if not isinstance(node, yaml.ScalarNode):
            raise self.error(node, f"{role} must be an expression (text), not a {'list' if isinstance(node, yaml.SequenceNode) else 'mapping'}")
        start, end = node.start_mark.index, node.end_mark.index
        offsets = align(node.value, self.source.text[start:end], start)
        return Snippet(node.value, self.source, role, offsets)

    def plain(self, node: yaml.Node) -> object:
        """The Python value of a node (lists, numbers, strings)."""
        try:
            return yaml.constructor.SafeConstructor().construct_document(node)
        except (yaml.YAMLError, ValueError, OverflowError) as exc:  # e.g. an integer of over 4300 digits, a bad date
            raise self.error(node, f"this value cannot be read: {exc}") from None

    def number(self, node: yaml.Node, role: str) -> Scalar:
        """A number: a YAML int or float, or a constant expression such as ``0x3080 + 0x1049``."""
        value: object = None
        if isinstance(node, yaml.ScalarNode) and node.tag in (_INT_TAG, _FLOAT_TAG):
            value = self.plain(node)
        if value is None or isinstance(value, bool):
            value = constant(parse(self.snippet(node, role)))
        if value is None:
            raise self.error(node, f"{role} must be a number or a constant arithmetic expression")
        return self._checked(node, role, value)  # type: ignore[arg-type]

    def _checked(self, node: yaml.Node, role: str, value: Scalar) -> Scalar:
        """Refuse what the scenario's code could not hold: inf, NaN, integers over 64 bits."""
        if isinstance(value, float) and not math.isfinite(value):
            raise self.error(node, f"expected {role} to be a finite number, got {value}")
        if isinstance(value, int) and abs(value) > MAX_INT:
            raise self.error(
                node, f"expected {role} to fit in 64 bits (at most {MAX_INT}), got a {value.bit_length()}-bit number"
            )
        return value

    def table(self, key: yaml.Node, node: yaml.Node) -> Table:
        name = key.value
        what = f"table {name!r}"
        entries = self.mapping(node, what, TABLE_KEYS)
        by = None
        if "by" in entries:
            by_value = self.plain(entries["by"][1])
            if not (isinstance(by_value, list) and by_value and all(isinstance(p, str) for p in by_value)):
                raise self.error(entries["by"][1], f"'by' of {what} must be a list of names, e.g. [zone, act]")
            by = tuple(by_value)
        default = self.number(entries["default"][1], f"the default of {what}") if "default" in entries else None
        if "values" not in entries:
            raise self.error(key, f"{what} needs 'values:', a mapping from keys such as '0, 1' to numbers")
        data: dict[tuple[Scalar, ...], Scalar] = {}
        arity = len(by) if by else None
        for text, (k, v) in self.mapping(entries["values"][1], f"the values of {what}").items():
            parts = tuple(self._key_part(k, part) for part in text.split(","))
            if arity is None:
                arity = len(parts)
            if len(parts) != arity:
                raise self.error(k, f"{what} is keyed by {arity} value{'s' if arity > 1 else ''}, and this key has {len(parts)}")
            data[parts] = self.number(v, f"the value of {what} at {text}")
        if arity is None:
            raise self.error(key, f"{what} has no values")
        origin = Snippet(name, self.source, what, tuple(range(key.start_mark.index, key.start_mark.index + len(name) + 1)))
        return Table(name, data, arity, by, default, origin)

    def _key_part(self, node: yaml.Node, part: str) -> Scalar:
        text = part.strip().replace("_", "")
        if len(text) <= 40:  # longer is no 64-bit number, and int() refuses over 4300 digits
            try:
                return self._checked(node, "a table key", int(text, 0))
            except ValueError:
                pass
            try:
                return self._checked(node, "a table key", float(text))
            except ValueError:
                pass
        raise self.error(
            node, f"a table key is one or more numbers separated by commas, e.g. '0, 1'; got {node.value[:40]!r}"
        )

    def name_snippet(self, key: yaml.Node, role: str) -> Snippet:
        start = key.start_mark.index
        return Snippet(key.value, self.source, role, tuple(range(start, start + len(key.value) + 1)))


class DocumentLoader:
    """Build a ScenarioSpec from a YAML file and the files it includes."""

    def __init__(self, name: str, *, resolve_include: Callable[[Path, str], Path] | None = None) -> None:
        self.spec = ScenarioSpec(name)
        self._origins: dict[str, Snippet] = {}
        self._seen: list[Path] = []
        #: Turns an ``include`` entry into a path, from the including file's folder; it may refuse one
        #: (raise a RetrokitError) that leaves the folders a caller allows, as the studio's requests must.
        self.resolve_include = resolve_include or (lambda base, name: base / name)

    def load_file(self, path: Path, *, top: bool = True) -> None:
        """Read ``path`` (a scenario, or an included file when ``top`` is false)."""
        source = read_source(path)  # first: a symlink loop is its error, before resolve() raises a raw one
        resolved = path.resolve()
        if resolved in self._seen:
            raise ScenarioError(f"{path}: included more than once (includes must not loop)")
        self._seen.append(resolved)
        self.load_source(source, path.parent, top=top)

    def load_text(self, text: str, name: str, base: Path | None, *, top: bool = True) -> None:
        """Read scenario YAML ``text``; ``name`` labels it in messages, ``base`` resolves includes."""
        self.load_source(SourceText(name, text), base, top=top)

    def load_source(self, source: SourceText, base: Path | None, *, top: bool = True) -> None:
        """Read scenario YAML from ``source``; ``base`` resolves includes."""
        reader = _Reader(source)
        root = reader.compose()
        if root is None:
            return
        entries = reader.mapping(root, "an included file" if not top else "a scenario", TOP_KEYS if top else INCLUDE_KEYS)
        spec = self.spec
        if "include" in entries:
            for item in self._list(reader, entries["include"][1], "include"):
                if base is None:
                    raise reader.error(entries["include"][1], "include needs a folder to look in: pass game_dir")
                try:
                    target = self.resolve_include(base, str(reader.plain(item)))
                except RetrokitError as exc:
                    raise reader.error(item, f"cannot include {str(reader.plain(item))!r}: {exc}") from None
                try:
                    found = target.is_file()
                except (OSError, ValueError):  # a name too long for the file system, or holding NUL
                    found = False
                if not found:
                    raise reader.error(item, f"no file {str(reader.plain(item))!r} to include (looked for {target})")
                self.load_file(target, top=False)
        if "name" in entries:
            spec.name = str(reader.plain(entries["name"][1]))
        if "tables" in entries:
            for table_name, (key, node) in reader.mapping(entries["tables"][1], "tables").items():
                table = reader.table(key, node)
                self._claim(table_name, table.origin, reader, key)
                spec.tables[table_name] = table
        if "define" in entries:
            for def_name, (key, node) in reader.mapping(entries["define"][1], "define").items():
                where = reader.name_snippet(key, f"define {def_name!r}")
                self._claim(def_name, where, reader, key)
                spec.defines[def_name] = reader.snippet(node, f"define {def_name!r}")
                spec.define_names[def_name] = where
        if "reward" in entries and "rewards" in entries:
            raise reader.error(entries["rewards"][0], "give either 'reward' (one player) or 'rewards' (a list, one per player), not both")
        if "reward" in entries:
            spec.rewards = [reader.snippet(entries["reward"][1], "reward")]
        if "rewards" in entries:
            items = self._list(reader, entries["rewards"][1], "rewards")
            spec.rewards = [reader.snippet(item, f"reward of player {i + 1}") for i, item in enumerate(items)]
        if "done" in entries:
            spec.done = reader.snippet(entries["done"][1], "done")
        if "dones" in entries:
            items = self._list(reader, entries["dones"][1], "dones")
            players = max(1, len(spec.rewards))
            if len(items) != players:
                raise reader.error(
                    entries["dones"][1],
                    f"expected one done condition per player ({players}, as many as the rewards), got {len(items)}",
                )
            spec.dones = [reader.snippet(item, f"done of player {i + 1}") for i, item in enumerate(items)]
        if "actions" in entries:
            spec.actions = self._actions(reader, entries["actions"][1])
        if "jump" in entries:
            jump = reader.plain(entries["jump"][1])
            if not isinstance(jump, str) or not jump:
                raise reader.error(entries["jump"][1], "jump is one button name, the one JERK jumps with, such as A")
            spec.jump = jump
        if "reset_ram" in entries:
            spec.reset_ram = self._reset_ram(reader, entries["reset_ram"][1])
        if "crop" in entries:
            crop = reader.plain(entries["crop"][1])
            if not (isinstance(crop, list) and len(crop) == 4 and all(isinstance(c, int) and not isinstance(c, bool) and c >= 0 for c in crop)):
                raise reader.error(entries["crop"][1], "crop is [x, y, width, height], four whole numbers of pixels")
            spec.crop = (crop[0], crop[1], crop[2], crop[3])

    def _claim(self, name: str, where: Snippet, reader: _Reader, key: yaml.Node) -> None:
        """Record where ``name`` is defined; a second table or definition of it is an error."""
        if name in self._origins:
            raise reader.error(key, f"{name!r} is already defined, at {self._origins[name].where()}")
        self._origins[name] = where

    @staticmethod
    def _list(reader: _Reader, node: yaml.Node, what: str) -> list[yaml.Node]:
        if not isinstance(node, yaml.SequenceNode) or not node.value:
            raise reader.error(node, f"{what} must be a non-empty list")
        return list(node.value)

    @staticmethod
    def _reset_ram(reader: _Reader, node: yaml.Node) -> dict[int, tuple[str, int, int]]:
        from retrokit.dsl.resetram import MAX_WRITES, draw_of

        entries = reader.mapping(node, "reset_ram")
        if not entries or len(entries) > MAX_WRITES:
            raise reader.error(node, f"reset_ram maps 1 to {MAX_WRITES} console addresses to what to write there")
        writes = {}
        for key_text, (key, value) in entries.items():
            address = reader.plain(key)
            if not isinstance(address, int) or isinstance(address, bool) or address < 0:
                raise reader.error(key, f"a reset_ram key is a console address, such as 0x0017; got {key_text!r}")
            if address in writes:
                raise reader.error(key, f"reset_ram gives address 0x{address:X} twice")
            try:
                writes[address] = draw_of(reader.plain(value))
            except RetrokitError as exc:
                raise reader.error(value, str(exc)) from None
        return writes

    @staticmethod
    def _actions(reader: _Reader, node: yaml.Node) -> list:
        actions = reader.plain(node)
        ok = isinstance(actions, list) and all(
            isinstance(group, list) and all(isinstance(combo, list) and all(isinstance(b, str) for b in combo) for combo in group)
            for group in actions
        )
        if not ok:
            raise reader.error(node, "actions is a list of groups, each a list of button combinations: [[[], [LEFT], [RIGHT]], [[], [B]]]")
        return actions


def load_document(path: str | os.PathLike[str], *, name: str | None = None) -> ScenarioSpec:
    """Read a scenario YAML file (and its includes) into a spec."""
    path = Path(path)
    loader = DocumentLoader(name or path.stem)
    loader.load_file(path)
    if name:
        loader.spec.name = name
    return loader.spec


def document_from_dict(data: dict, *, name: str | None = None, game_dir: str | os.PathLike[str] | None = None) -> ScenarioSpec:
    """Build a spec from an already-parsed scenario dict.

    The dict is written back as YAML and read like a file named
    ``<scenario NAME>``, so its errors point at lines of that text.
    """
    label = name or str(data.get("name", "scenario"))
    try:
        text = yaml.safe_dump(plain_scenario_dict(data, label), sort_keys=False, default_flow_style=False, width=10_000)
    except yaml.YAMLError as exc:  # RepresenterError: an object YAML cannot write
        found = exc.args[1] if len(exc.args) > 1 else exc
        raise ScenarioError(
            f"scenario {label!r}: expected plain values (text, numbers, lists, dicts), got {shown(found)} "
            f"({type(found).__name__}); pass expressions as text"
        ) from None
    loader = DocumentLoader(label)
    loader.load_text(text, f"<scenario {label!r}>", Path(game_dir) if game_dir is not None else None)
    if name:
        loader.spec.name = name
    return loader.spec


#: How deep a scenario given as a dict may nest: the deepest shipped one nests 5 levels.
MAX_DICT_DEPTH = 100


def plain_scenario_dict(data: Mapping, label: str = "scenario") -> dict:
    """Copy a scenario given as a dict into plain values YAML can write, checking its shape.

    Tuple keys ``(0, 1)`` become ``"0, 1"``, numpy values Python ones.

    Raises:
        ScenarioError: The dict contains itself, or nests deeper than :data:`MAX_DICT_DEPTH`
            (either would exhaust Python's stack while it is read).
    """
    return _plain_keys(data, label, 0, set())  # type: ignore[return-value]


def _plain_keys(value: object, label: str, depth: int, path: set[int]) -> object:
    if isinstance(value, (Mapping, list, tuple)):
        if id(value) in path:
            raise ScenarioError(
                f"scenario {label!r}: expected a tree of plain values; found a dict or list that contains itself. "
                "Pass a copy without the loop"
            )
        if depth >= MAX_DICT_DEPTH:
            raise ScenarioError(
                f"scenario {label!r}: expected dicts and lists nested at most {MAX_DICT_DEPTH} deep; found deeper "
                "ones. A scenario nests a few levels: check what was passed"
            )
        path.add(id(value))
        try:
            if isinstance(value, Mapping):
                return {
                    (", ".join(str(p) for p in k) if isinstance(k, tuple) else k): _plain_keys(v, label, depth + 1, path)
                    for k, v in value.items()
                }
            return [_plain_keys(v, label, depth + 1, path) for v in value]
        finally:
            path.discard(id(value))
    if isinstance(value, (np.generic, np.ndarray)):  # np.int64(3), np.array([0, 0, 320, 224])
        return _plain_keys(value.tolist(), label, depth, path)
    return value
