"""The syntax tree of scenario expressions.

Every node records ``start`` and ``end``, character offsets into its
expression's text, so that any later error can point at it. ``key()`` gives a
canonical text of a subtree without positions: equal keys mean equal
expressions, which lets the compiler share one memory slot between repeated
``prev(lives)``.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, kw_only=True)
class Node:
    """Base of every expression node."""

    start: int
    end: int

    def key(self) -> str:
        """Canonical text of the subtree, without positions."""
        raise NotImplementedError

    def children(self) -> tuple[Node, ...]:
        """The direct sub-expressions, in source order."""
        return ()


@dataclass(frozen=True, kw_only=True)
class Number(Node):
    """An integer, hex or decimal literal."""

    value: int | float

    def key(self) -> str:
        return repr(self.value)


@dataclass(frozen=True, kw_only=True)
class Bool(Node):
    """``true`` or ``false``."""

    value: bool

    def key(self) -> str:
        return "true" if self.value else "false"


@dataclass(frozen=True, kw_only=True)
class Name(Node):
    """A field, a definition or a time counter; ``quoted`` for a `backquoted` name."""

    id: str
    quoted: bool = False

    def key(self) -> str:
        return f"`{self.id}`" if self.quoted else self.id


@dataclass(frozen=True, kw_only=True)
class Call(Node):
    """A built-in function call; ``name_end`` ends the function's name."""

    func: str
    name_end: int
    args: tuple[Node, ...]

    def key(self) -> str:
        return f"{self.func}({', '.join(a.key() for a in self.args)})"

    def children(self) -> tuple[Node, ...]:
        return self.args


@dataclass(frozen=True, kw_only=True)
class Lookup(Node):
    """A table lookup ``table[key, ...]``; ``name_end`` ends the table's name."""

    table: str
    name_end: int
    keys: tuple[Node, ...]

    def key(self) -> str:
        return f"{self.table}[{', '.join(k.key() for k in self.keys)}]"

    def children(self) -> tuple[Node, ...]:
        return self.keys


@dataclass(frozen=True, kw_only=True)
class Unary(Node):
    """``-x``, ``+x`` or ``~x``."""

    op: str
    operand: Node

    def key(self) -> str:
        return f"({self.op}{self.operand.key()})"

    def children(self) -> tuple[Node, ...]:
        return (self.operand,)


@dataclass(frozen=True, kw_only=True)
class Binary(Node):
    """An arithmetic or bit operation; ``op_start`` is where the operator is written."""

    op: str
    op_start: int
    left: Node
    right: Node

    def key(self) -> str:
        return f"({self.left.key()} {self.op} {self.right.key()})"

    def children(self) -> tuple[Node, ...]:
        return (self.left, self.right)


@dataclass(frozen=True, kw_only=True)
class Compare(Node):
    """A comparison, possibly chained: ``0 < x <= 10``."""

    ops: tuple[str, ...]
    operands: tuple[Node, ...]

    def key(self) -> str:
        parts = [self.operands[0].key()]
        for op, operand in zip(self.ops, self.operands[1:]):
            parts += [op, operand.key()]
        return f"({' '.join(parts)})"

    def children(self) -> tuple[Node, ...]:
        return self.operands


@dataclass(frozen=True, kw_only=True)
class Logic(Node):
    """``a and b`` or ``a or b``."""

    op: str
    left: Node
    right: Node

    def key(self) -> str:
        return f"({self.left.key()} {self.op} {self.right.key()})"

    def children(self) -> tuple[Node, ...]:
        return (self.left, self.right)


@dataclass(frozen=True, kw_only=True)
class Not(Node):
    """``not a``."""

    operand: Node

    def key(self) -> str:
        return f"(not {self.operand.key()})"

    def children(self) -> tuple[Node, ...]:
        return (self.operand,)


@dataclass(frozen=True, kw_only=True)
class IfElse(Node):
    """``then if cond else other``."""

    cond: Node
    then: Node
    other: Node

    def key(self) -> str:
        return f"({self.then.key()} if {self.cond.key()} else {self.other.key()})"

    def children(self) -> tuple[Node, ...]:
        return (self.then, self.cond, self.other)


def walk(node: Node):
    """Yield ``node`` and every node below it, parents first."""
    stack = [node]
    while stack:
        current = stack.pop()
        yield current
        stack.extend(reversed(current.children()))
