"""Check scenario expressions before anything runs.

:class:`Checker` parses every expression of a :class:`ScenarioSpec` and checks
it: every name is a field, a definition or a time counter; every function and
table exists and gets the right number of arguments; and no division is by a
constant zero. Types are checked afterwards, by :mod:`retrokit.dsl.typecheck`,
over the analysis this module makes; the type names it uses live here.

It also gives every memory call (``prev``, ``delta``, ``initial``, ``peak``)
a :class:`Slot`; equal calls share one.
"""

from __future__ import annotations

import operator
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

from retrokit.dsl import nodes as n
from retrokit.dsl.parser import parse
from retrokit.dsl.source import Snippet
from retrokit.dsl.spec import ScenarioSpec, Table
from retrokit.errors import ScenarioCompileError, did_you_mean

INT, FLOAT, BOOL = "integer", "decimal", "boolean"
NUMBERS = (INT, FLOAT)

#: Names that are always the time counters: emulator frames and env steps since reset.
COUNTERS = ("frame", "step")
RESERVED = frozenset({"and", "or", "not", "if", "else", "true", "false", *COUNTERS})

#: Memory functions: their argument's value at other steps.
MEMORY = ("prev", "delta", "initial", "peak")


@dataclass(frozen=True)
class Function:
    """A built-in function's arity and how to call it, for messages."""

    min_args: int
    max_args: int | None
    usage: str


FUNCTIONS = {
    "abs": Function(1, 1, "abs(x)"),
    "sign": Function(1, 1, "sign(x)"),
    "min": Function(2, None, "min(a, b, ...)"),
    "max": Function(2, None, "max(a, b, ...)"),
    "clip": Function(3, 3, "clip(x, low, high)"),
    "prev": Function(1, 2, "prev(x) or prev(x, value_at_reset)"),
    "delta": Function(1, 2, "delta(x) or delta(x, previous_at_reset)"),
    "initial": Function(1, 1, "initial(x)"),
    "peak": Function(1, 1, "peak(x)"),
}

_ARITHMETIC = {
    "+": operator.add, "-": operator.sub, "*": operator.mul, "/": operator.truediv,
    "//": operator.floordiv, "%": operator.mod, "&": operator.and_, "|": operator.or_,
    "^": operator.xor, "<<": operator.lshift, ">>": operator.rshift,
}
_UNARY = {"-": operator.neg, "+": operator.pos, "~": operator.invert}
_DIVISIONS = ("/", "//", "%")
_BITS = ("&", "|", "^", "<<", ">>")


@dataclass
class Slot:
    """The state of one memory call, e.g. ``prev(lives, 3)``.

    Attributes:
        index: Position in a Run's state list.
        kind: One of :data:`MEMORY`.
        arg: The expression remembered.
        default: ``prev``'s or ``delta``'s value standing for the previous one at reset.
        snippet: Where the call is first written.
    """

    index: int
    kind: str
    arg: n.Node
    default: n.Node | None
    snippet: Snippet


@dataclass
class Analysis:
    """A checked scenario: syntax trees, the fields it reads, its memory slots and types."""

    spec: ScenarioSpec
    defines: dict[str, n.Node]
    rewards: list[n.Node]
    done: n.Node | None
    dones: list[n.Node] = field(default_factory=list)
    fields: list[str] = field(default_factory=list)
    slots: dict[str, Slot] = field(default_factory=dict)
    types: dict[str, str] = field(default_factory=dict)


def constant(node: n.Node) -> int | float | None:
    """Return the value of a constant arithmetic expression, else ``None``."""
    if isinstance(node, n.Number):
        return node.value
    if isinstance(node, n.Unary):
        value = constant(node.operand)
        return None if value is None or (node.op == "~" and not isinstance(value, int)) else _UNARY[node.op](value)
    if isinstance(node, n.Binary):
        left, right = constant(node.left), constant(node.right)
        if left is None or right is None or (node.op in _DIVISIONS and right == 0):
            return None
        if node.op in _BITS and not (isinstance(left, int) and isinstance(right, int)):
            return None
        if node.op in ("<<", ">>") and not 0 <= right <= 64:
            return None
        return _ARITHMETIC[node.op](left, right)
    return None


MAX_DEFINES = 4000
"""The most definitions a scenario may hold: hand-written ones have tens; each costs its own generated code."""
MAX_NODES = 50_000
"""The most nodes (operators, names, numbers) in all of a scenario's expressions: the Sonic contest's hold a few hundred."""


_ATOM = re.compile(r"[A-Za-z_0-9][A-Za-z_0-9.]*")


def _count(root: n.Node) -> int:
    """How many nodes an expression holds."""
    count, stack = 0, [root]
    while stack:
        node = stack.pop()
        count += 1
        stack.extend(node.children())
    return count


class Checker:
    """Resolve names, check arity and constants, collect slots, infer types."""

    def __init__(self, spec: ScenarioSpec, fields: Sequence[str]) -> None:
        self.spec = spec
        self.fields = list(fields)
        self._field_set = set(fields)
        self._used_fields: dict[str, None] = {}
        self.slots: dict[str, Slot] = {}
        self._nodes = 0  # in the expressions parsed so far

    def run(self) -> Analysis:
        """Check everything and return the analysis (types included)."""
        spec = self.spec
        for count, (name, where) in enumerate(spec.define_names.items(), 1):
            if count > MAX_DEFINES:  # each costs its own code: 40,000 took a gigabyte to compile
                raise where.error(
                    ScenarioCompileError, 0, len(where.text),
                    f"expected at most {MAX_DEFINES} definitions in a scenario; found more (this is number {count}). "
                    "Use tables for long lists of values, or fewer steps",
                )
            self._check_define_name(name, where)
        defines = {name: self._parse(snippet) for name, snippet in spec.defines.items()}
        rewards = [self._parse(snippet) for snippet in spec.rewards]
        done = self._parse(spec.done) if spec.done is not None else None
        dones = [self._parse(snippet) for snippet in spec.dones]
        analysis = Analysis(spec, defines, rewards, done, dones)
        analysis.fields = list(self._used_fields)
        analysis.slots = self.slots
        return analysis

    def _check_define_name(self, name: str, where: Snippet) -> None:
        if name in RESERVED:
            raise where.error(ScenarioCompileError, 0, len(where.text), f"{name!r} is a reserved word; choose another name")
        if name in self._field_set:
            raise where.error(
                ScenarioCompileError, 0, len(where.text),
                f"{name!r} is already a field of this game; choose another name for the definition",
            )
        if name in self.spec.tables:
            raise where.error(ScenarioCompileError, 0, len(where.text), f"{name!r} is already a table; choose another name")

    def _parse(self, snippet: Snippet) -> n.Node:
        # Each name or number is a node: counted in the text first, as parsing a megabyte of them takes 500 MB.
        atoms = sum(1 for word in _ATOM.findall(snippet.text) if word != "else")  # `a if c else b`: 4 nodes
        root = parse(snippet) if self._nodes + atoms <= MAX_NODES else None
        self._nodes += atoms if root is None else _count(root)
        if self._nodes > MAX_NODES:  # the generated code, and Python's compile of it, grows with them
            raise snippet.error(
                ScenarioCompileError, 0, len(snippet.text),
                f"expected at most {MAX_NODES} operators, names and numbers in a scenario's expressions; found more "
                "by this one. Split the scenario, or use tables",
            )
        self._resolve(root, snippet)  # type: ignore[arg-type] - not None: the count is within the cap
        return root  # type: ignore[return-value]

    def _resolve(self, node: n.Node, sn: Snippet) -> None:
        for child in node.children():
            self._resolve(child, sn)
        if isinstance(node, n.Name):
            self._resolve_name(node, sn)
        elif isinstance(node, n.Call):
            self._resolve_call(node, sn)
        elif isinstance(node, n.Lookup):
            self._resolve_lookup(node, sn)
        elif isinstance(node, n.Binary) and node.op in _DIVISIONS and constant(node.right) == 0:
            what = {"/": "division", "//": "floor division", "%": "remainder"}[node.op]
            raise sn.error(ScenarioCompileError, node.right.start, node.right.end, f"{what} by zero: the divisor is the constant 0")

    def _resolve_name(self, node: n.Name, sn: Snippet) -> None:
        name = node.id
        if (not node.quoted and name in COUNTERS) or name in self.spec.defines:
            return
        if name in self._field_set:
            self._used_fields[name] = None
            return
        if name in self.spec.tables:
            message = f"{name!r} is a table; look a value up with {name}[...]"
        elif name in FUNCTIONS:
            message = f"{name!r} is a function; call it: {FUNCTIONS[name].usage}"
        else:
            known = [*self.fields, *self.spec.defines, *COUNTERS]
            message = f"unknown field or definition {name!r}." + did_you_mean(name, known)
            if not self.fields:
                message += " (The game's data file gives no fields.)"
        raise sn.error(ScenarioCompileError, node.start, node.end, message)

    def _resolve_call(self, node: n.Call, sn: Snippet) -> None:
        function = FUNCTIONS.get(node.func)
        if function is None:
            if node.func in self.spec.tables:
                message = f"{node.func!r} is a table: look values up with square brackets, {node.func}[...]"
            else:
                message = f"unknown function {node.func!r}." + did_you_mean(node.func, FUNCTIONS)
            raise sn.error(ScenarioCompileError, node.start, node.name_end, message)
        count = len(node.args)
        if count < function.min_args or (function.max_args is not None and count > function.max_args):
            if function.max_args is None:
                wanted = f"at least {function.min_args}"
            elif function.min_args == function.max_args:
                wanted = str(function.min_args)
            else:
                wanted = f"{function.min_args} or {function.max_args}"
            message = f"{node.func}() takes {wanted} argument{'s' if wanted != '1' else ''}, got {count}: write {function.usage}"
            raise sn.error(ScenarioCompileError, node.start, node.end, message)
        if node.func in MEMORY:
            key = node.key()
            if key not in self.slots:
                default = node.args[1] if count > 1 else None
                self.slots[key] = Slot(len(self.slots), node.func, node.args[0], default, sn)

    def _resolve_lookup(self, node: n.Lookup, sn: Snippet) -> None:
        table = self.spec.tables.get(node.table)
        if table is None:
            if node.table in FUNCTIONS:
                message = f"{node.table!r} is a function: call it with parentheses, {FUNCTIONS[node.table].usage}"
            else:
                message = f"unknown table {node.table!r}." + did_you_mean(node.table, self.spec.tables)
                if not self.spec.tables:
                    message += " (This scenario defines no tables.)"
            raise sn.error(ScenarioCompileError, node.start, node.name_end, message)
        if len(node.keys) != table.arity:
            parts = f" ({', '.join(table.by)})" if table.by else ""
            message = f"table {table.name!r} is keyed by {table.arity} value{'s' if table.arity > 1 else ''}{parts}, got {len(node.keys)}"
            raise sn.error(ScenarioCompileError, node.start, node.end, message)


def table_type(table: Table) -> str:
    """A table's value type: integer unless some value (or the default) is decimal."""
    values = [*table.entries.values(), *([table.default] if table.default is not None else [])]
    return FLOAT if any(isinstance(v, float) for v in values) else INT
