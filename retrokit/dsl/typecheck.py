"""Infer and check the types of a scenario's expressions.

Types are :data:`~retrokit.dsl.check.INT`, :data:`~retrokit.dsl.check.FLOAT`
(both numbers) and :data:`~retrokit.dsl.check.BOOL`. Fields, counters and
integer literals are integers; ``/`` gives a decimal; comparisons, ``and``,
``or`` and ``not`` give booleans. A definition that refers to itself through
``prev(x, default)`` takes the default's type until its own is known, so types
are inferred in passes until they stop changing (a type can only widen from
integer to decimal, so this ends).
"""

from __future__ import annotations

from retrokit.dsl import nodes as n
from retrokit.dsl.check import BOOL, COUNTERS, FLOAT, INT, NUMBERS, Analysis, table_type
from retrokit.dsl.graph import Graph
from retrokit.dsl.source import Snippet
from retrokit.errors import ScenarioCompileError

_COUNT_HINT = "to count a condition as a number, write (1 if condition else 0)"
_TEST_HINT = "compare the number to make a condition, e.g. x != 0"


class _Pending(Exception):
    """A definition's type is asked while it is being inferred."""


def join(a: str, b: str) -> str:
    """The type holding both ``a`` and ``b``: integer and decimal join to decimal."""
    if a == b:
        return a
    return FLOAT


class TypeChecker:
    """Infer every definition's type and check every expression."""

    def __init__(self, analysis: Analysis) -> None:
        self.a = analysis
        self.types: dict[str, str] = {}
        self._settled: set[str] = set()
        self._busy: set[str] = set()

    def run(self) -> None:
        """Check all expressions; store definition and reward types in the analysis."""
        a = self.a
        # In dependency order, each definition finds the ones it reads typed
        # already, so inference recurses only as deep as one expression.
        order = Graph(a).definition_order()
        for _ in range(8):
            before = dict(self.types)
            self._settled.clear()
            for name in order:
                self.define_type(name)
            if self.types == before:
                break
        for root, snippet in zip(a.rewards, a.spec.rewards):
            if self.type_of(root, snippet) == BOOL:
                raise snippet.error(
                    ScenarioCompileError, root.start, root.end,
                    f"a reward must be a number, and this is a condition (boolean); {_COUNT_HINT}",
                )
        if a.done is not None:
            assert a.spec.done is not None
            if self.type_of(a.done, a.spec.done) != BOOL:
                raise a.spec.done.error(
                    ScenarioCompileError, a.done.start, a.done.end,
                    f"done must be a condition (boolean), and this is a number; {_TEST_HINT}",
                )
        for root, snippet in zip(a.dones, a.spec.dones):
            if self.type_of(root, snippet) != BOOL:
                raise snippet.error(
                    ScenarioCompileError, root.start, root.end,
                    f"a player's done must be a condition (boolean), and this is a number; {_TEST_HINT}",
                )
        a.types = dict(self.types)

    def define_type(self, name: str) -> str:
        """The type of definition ``name``, inferring it if needed."""
        if name in self._settled:
            return self.types[name]
        if name in self._busy:
            if name in self.types:
                return self.types[name]
            raise _Pending
        self._busy.add(name)
        try:
            kind = self.type_of(self.a.defines[name], self.a.spec.defines[name])
        finally:
            self._busy.discard(name)
        self.types[name] = join(self.types[name], kind) if name in self.types and kind != BOOL else kind
        self._settled.add(name)
        return self.types[name]

    def type_of(self, node: n.Node, sn: Snippet) -> str:
        """Check ``node`` and return its type."""
        if isinstance(node, n.Number):
            return INT if isinstance(node.value, int) else FLOAT
        if isinstance(node, n.Bool):
            return BOOL
        if isinstance(node, n.Name):
            if not node.quoted and node.id in COUNTERS:
                return INT
            if node.id in self.a.defines:
                return self.define_type(node.id)
            return INT
        if isinstance(node, n.Unary):
            kind = self.number(node.operand, sn, f"'{node.op}'")
            if node.op == "~":
                self.integer(node.operand, sn, kind, "'~'")
            return kind
        if isinstance(node, n.Binary):
            return self._binary(node, sn)
        if isinstance(node, n.Compare):
            self._compare(node, sn)
            return BOOL
        if isinstance(node, n.Logic):
            self.boolean(node.left, sn, f"'{node.op}'")
            self.boolean(node.right, sn, f"'{node.op}'")
            return BOOL
        if isinstance(node, n.Not):
            self.boolean(node.operand, sn, "'not'")
            return BOOL
        if isinstance(node, n.IfElse):
            self.boolean(node.cond, sn, "the condition of 'if'")
            return self.same_kind(node.then, node.other, sn, "the two branches of 'if ... else'")
        if isinstance(node, n.Lookup):
            for key in node.keys:
                self.number(key, sn, f"a key of table {node.table!r}")
            return table_type(self.a.spec.tables[node.table])
        if isinstance(node, n.Call):
            return self._call(node, sn)
        raise AssertionError(node)

    def _binary(self, node: n.Binary, sn: Snippet) -> str:
        what = f"'{node.op}'"
        left = self.number(node.left, sn, what)
        right = self.number(node.right, sn, what)
        if node.op in ("&", "|", "^", "<<", ">>"):
            self.integer(node.left, sn, left, what)
            self.integer(node.right, sn, right, what)
            return INT
        return FLOAT if node.op == "/" else join(left, right)

    def _compare(self, node: n.Compare, sn: Snippet) -> None:
        for op, left, right in zip(node.ops, node.operands, node.operands[1:]):
            if op in ("==", "!="):
                self.same_kind(left, right, sn, f"the two sides of '{op}'")
            else:
                self.number(left, sn, f"'{op}'")
                self.number(right, sn, f"'{op}'")

    def _call(self, node: n.Call, sn: Snippet) -> str:
        func, args = node.func, node.args
        what = f"{func}()"
        if func == "prev" and len(args) == 2:
            default = self.type_of(args[1], sn)
            try:
                value = self.type_of(args[0], sn)
            except _Pending:
                return default
            return self._same(args[0], args[1], value, default, sn, f"the value and the default of {what}")
        if func in ("prev", "initial"):
            return self.type_of(args[0], sn)
        if func == "sign":
            self.number(args[0], sn, what)
            return INT
        kinds = [self.number(arg, sn, what) for arg in args]
        kind = kinds[0]
        for other in kinds[1:]:
            kind = join(kind, other)
        return kind

    def same_kind(self, left: n.Node, right: n.Node, sn: Snippet, what: str) -> str:
        """Check two operands are both numbers or both conditions; return their join."""
        return self._same(left, right, self.type_of(left, sn), self.type_of(right, sn), sn, what)

    @staticmethod
    def _same(left: n.Node, right: n.Node, lt: str, rt: str, sn: Snippet, what: str) -> str:
        if (lt == BOOL) != (rt == BOOL):
            message = (
                f"{what} must both be numbers or both be conditions: "
                f"this is a {'condition (boolean)' if rt == BOOL else 'number'}, "
                f"the other a {'condition (boolean)' if lt == BOOL else 'number'}"
            )
            raise sn.error(ScenarioCompileError, right.start, right.end, message)
        return join(lt, rt)

    def number(self, node: n.Node, sn: Snippet, what: str) -> str:
        """Check ``node`` is a number and return its type."""
        kind = self.type_of(node, sn)
        if kind not in NUMBERS:
            raise sn.error(
                ScenarioCompileError, node.start, node.end,
                f"a condition (boolean) is used where a number is needed, by {what}; {_COUNT_HINT}",
            )
        return kind

    def boolean(self, node: n.Node, sn: Snippet, what: str) -> None:
        """Check ``node`` is a condition."""
        if self.type_of(node, sn) != BOOL:
            raise sn.error(
                ScenarioCompileError, node.start, node.end,
                f"a number is used where a condition (boolean) is needed, by {what}; {_TEST_HINT}",
            )

    @staticmethod
    def integer(node: n.Node, sn: Snippet, kind: str, what: str) -> None:
        """Check a number is an integer (for bit operations)."""
        if kind != INT:
            raise sn.error(
                ScenarioCompileError, node.start, node.end,
                f"{what} needs integers, and this is a decimal number (made by '/' or a decimal literal)",
            )
