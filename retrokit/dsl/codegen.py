"""Generate the Python source of a checked scenario.

The output is one function, ``_bind(s, d)``, that closes over a Run's state
list ``s`` and its list of per-player dones ``d`` (written each step when the
scenario has ``dones``), and returns two step functions, ``_first`` (reset)
and ``_next`` (every later step), each ``(v, frame, step) -> ((reward, ...),
done)``. Their bodies
are straight-line code: read the fields the scenario uses from ``v``, compute
the definitions and memory arguments in dependency order, then the outputs,
then store the slots. No user text reaches the code except numbers: fields are
read by their ``repr``, everything else has a generated name.

Run-time failures are checked inline where they can happen, so the message can
name the expression: a division tests its divisor (``_divzero(site)``) unless
it is a constant (never zero: the checker refuses that), and a table lookup
tests for a missing key (``_nokey(site, key)``). A reward that is not a finite
number (an overflow to inf, a NaN) is refused (``_nonfinite(player, value)``).
Integers are 64-bit: each definition's and memory's value is tested against
:data:`INT_MIN` and :data:`INT_MAX` (``_overflow(site, value)``), and a shift
by a count that is not a constant from 0 to 63 tests it first
(``_shift(site, count)``), so no value grows from step to step without bound
and no step builds a huge number. Within one expression an intermediate may
be wider (an expression is a few operations: its size bounds it).
Python's compiler refuses code nested 200 brackets deep, so an expression whose
code would nest deeper than :data:`MAX_NESTING` is refused at compile time.
"""

from __future__ import annotations

from dataclasses import dataclass

from retrokit.dsl import nodes as n
from retrokit.dsl.check import COUNTERS, MEMORY, Analysis, constant
from retrokit.dsl.graph import FIRST, NEXT, Graph
from retrokit.dsl.source import Snippet
from retrokit.errors import ScenarioCompileError

#: CPython refuses code nesting 200 brackets deep; generated code stays below this.
MAX_NESTING = 180
#: The integers a scenario computes with: 64 bits, signed or unsigned, as fields and literals are.
INT_MIN = -(2**63)
INT_MAX = 2**64 - 1


def nesting(code: str) -> int:
    """How deep brackets nest in generated code (it holds no strings, so every bracket counts)."""
    depth = deepest = 0
    for ch in code:
        if ch in "([{":
            depth += 1
            deepest = max(deepest, depth)
        elif ch in ")]}":
            depth -= 1
    return deepest


#: Operators whose result can leave 64 bits when their operands are inside: (2**64 - 1) * 2, -(2**64 - 1), ...
_WIDENING = frozenset({"+", "-", "*", "<<", "|", "^", "//", "%", "~"})


def may_overflow(node: n.Node) -> bool:
    """Whether ``node`` can give an integer outside 64 bits when every name it reads is inside.

    Fields and literals are 64-bit; definitions and memories are tested where
    they are computed; so only arithmetic can leave the range, and a choice
    (``if``, ``min``, ``clip``, a table) only if one of its choices can.
    """
    value = constant(node)
    if value is not None:
        return isinstance(value, int) and not INT_MIN <= value <= INT_MAX
    if isinstance(node, n.Unary):
        return node.op != "+" or may_overflow(node.operand)
    if isinstance(node, n.Binary):
        if node.op == "/":
            return False  # a float
        return node.op in _WIDENING or may_overflow(node.left) or may_overflow(node.right)
    if isinstance(node, n.IfElse):
        return may_overflow(node.then) or may_overflow(node.other)
    if isinstance(node, n.Call):
        if node.func == "delta":
            return True
        if node.func == "prev":  # at reset, prev(x, default) is the default
            return len(node.args) > 1 and may_overflow(node.args[1])
        if node.func in ("initial", "peak", "sign"):
            return False
        return any(may_overflow(arg) for arg in node.args)  # abs, min, max, clip: one of their arguments
    return False  # names, numbers, conditions, table values


@dataclass(frozen=True)
class Site:
    """A place that can fail at run time: a division or a table lookup."""

    snippet: Snippet
    node: n.Node


class CodeGen:
    """Write the ``_bind`` function for one analysed scenario."""

    def __init__(self, analysis: Analysis) -> None:
        self.a = analysis
        self.graph = Graph(analysis)
        self.defs = {name: f"_d{i}" for i, name in enumerate(analysis.defines)}
        self.table_names = {name: f"_T{i}" for i, name in enumerate(analysis.spec.tables)}
        self.sites: list[Site] = []
        self._fields: dict[str, str] = {}
        self._temps = 0

    def module(self) -> str:
        """Return the source text of ``_bind``."""
        lines = ["def _bind(s, d):"]
        for name, mode in (("_first", FIRST), ("_next", NEXT)):
            lines += ["    " + line for line in self.function(name, mode)]
        lines.append("    return _first, _next")
        return "\n".join(lines) + "\n"

    def function(self, name: str, mode: str) -> list[str]:
        """One step function's lines."""
        self._fields = {}
        body: list[str] = []
        writes: list[str] = []
        slots = {slot.index: slot for slot in self.a.slots.values()}
        for kind, key in self.graph.order(mode):
            if kind == "def":
                snippet = self.a.spec.defines[key]  # type: ignore[index]
                root = self.a.defines[key]  # type: ignore[index]
                local = self.defs[key]  # type: ignore[index]
                body.append(f"{local} = {self.whole(root, mode, snippet)}")
                body += self.bounded(local, snippet, root)
                continue
            slot = slots[key]  # type: ignore[index]
            i = slot.index
            body.append(f"_m{i} = {self.whole(slot.arg, mode, slot.snippet)}")
            body += self.bounded(f"_m{i}", slot.snippet, slot.arg)
            if mode == NEXT and slot.kind == "peak":
                body.append(f"_p{i} = _m{i} if _m{i} > s[{i}] else s[{i}]")
                writes.append(f"s[{i}] = _p{i}")
            else:
                writes.append(f"s[{i}] = _m{i}")
        rewards = []
        for i, (root, snippet) in enumerate(zip(self.a.rewards, self.a.spec.rewards)):
            body.append(f"_r{i} = _float({self.whole(root, mode, snippet)})")
            # x - x is 0.0 for a finite x, NaN (true) for inf or NaN: one subtraction a step.
            body.append(f"if _r{i} - _r{i}: _nonfinite({i}, _r{i})")
            rewards.append(f"_r{i}")
        if not rewards:  # no reward given: 0 for the one player
            rewards.append("0.0")
        players = []
        for i, (root, snippet) in enumerate(zip(self.a.dones, self.a.spec.dones)):
            body.append(f"_pd{i} = {self.whole(root, mode, snippet)}")
            writes.append(f"d[{i}] = _pd{i}")
            players.append(f"_pd{i}")
        everyone_out = " and ".join(players)  # the episode also ends once every player is out
        if self.a.done is not None:
            assert self.a.spec.done is not None
            done = self.whole(self.a.done, mode, self.a.spec.done)
            body.append(f"_done = {done} or ({everyone_out})" if players else f"_done = {done}")
        else:
            body.append(f"_done = {everyone_out}" if players else "_done = False")
        loads = [f"{local} = v[{field!r}]" for field, local in self._fields.items()]
        out = [f"def {name}(v, frame, step):", "    try:"]
        out += ["        " + line for line in loads + body + writes]
        out.append(f"        return ({', '.join(rewards)},), _done")
        out += [
            "    except _RuntimeError:",
            "        raise",
            "    except _KeyError as exc:",
            "        raise _missing(exc) from None",
            "    except _Errors as exc:",
            "        raise _fail(exc) from None",
        ]
        return out

    def bounded(self, local: str, snippet: Snippet, node: n.Node) -> list[str]:
        """The statement refusing an integer outside 64 bits in ``local`` (a definition's or a memory's value).

        One chained comparison, and only where ``node`` can leave the range
        (:func:`may_overflow`): copies, choices and conditions need none, so
        a step of Sonic's contest scenario makes one test. Floats and booleans
        pass it too (a float out of range goes to ``_overflow``, which lets it through).
        """
        if not may_overflow(node):
            return []
        return [f"if not {INT_MIN} <= {local} <= {INT_MAX}: _overflow({self.site(snippet, node)}, {local})"]

    def temp(self, prefix: str) -> str:
        """A fresh local name."""
        self._temps += 1
        return f"{prefix}{self._temps}"

    def site(self, snippet: Snippet, node: n.Node) -> int:
        """Register a place that can fail at run time; return its index."""
        self.sites.append(Site(snippet, node))
        return len(self.sites) - 1

    def field(self, name: str) -> str:
        """The local holding a field's value (read once at the top)."""
        if name not in self._fields:
            self._fields[name] = f"_f{len(self._fields)}"
        return self._fields[name]

    def whole(self, node: n.Node, mode: str, sn: Snippet) -> str:
        """A whole expression's code for one statement, refused if Python could not compile it."""
        code = self.expr(node, mode, sn)
        depth = nesting(code)
        if depth > MAX_NESTING:
            raise sn.error(
                ScenarioCompileError, node.start, node.end,
                f"expected an expression Python can compile (at most {MAX_NESTING} brackets deep once generated), "
                f"got one generating {depth}; split it into definitions under 'define:'",
            )
        return code

    def expr(self, node: n.Node, mode: str, sn: Snippet) -> str:
        """The Python expression computing ``node`` in ``mode``."""
        if isinstance(node, n.Number):
            return repr(node.value)
        if isinstance(node, n.Bool):
            return "True" if node.value else "False"
        if isinstance(node, n.Name):
            if not node.quoted and node.id in COUNTERS:
                return node.id
            if node.id in self.defs:
                return self.defs[node.id]
            return self.field(node.id)
        if isinstance(node, n.Unary):
            return f"({node.op}{self.expr(node.operand, mode, sn)})"
        if isinstance(node, n.Binary):
            left, right = self.expr(node.left, mode, sn), self.expr(node.right, mode, sn)
            if node.op in ("/", "//", "%") and constant(node.right) is None:
                z = self.temp("_z")
                return f"({left} {node.op} {z} if ({z} := {right}) else _divzero({self.site(sn, node)}))"
            count = constant(node.right)
            if node.op == "<<" and not (isinstance(count, int) and 0 <= count < 64):
                # Tested before shifting: 1 << (frame * 10**8) would build a number of 12.5 MB a step.
                z = self.temp("_z")
                return f"({left} << {z} if 0 <= ({z} := {right}) < 64 else _shift({self.site(sn, node)}, {z}))"
            return f"({left} {node.op} {right})"
        if isinstance(node, n.Compare):
            parts = [self.expr(node.operands[0], mode, sn)]
            for op, operand in zip(node.ops, node.operands[1:]):
                parts += [op, self.expr(operand, mode, sn)]
            return f"({' '.join(parts)})"
        if isinstance(node, n.Logic):
            return f"({self.expr(node.left, mode, sn)} {node.op} {self.expr(node.right, mode, sn)})"
        if isinstance(node, n.Not):
            return f"(not {self.expr(node.operand, mode, sn)})"
        if isinstance(node, n.IfElse):
            cond, then, other = (self.expr(x, mode, sn) for x in (node.cond, node.then, node.other))
            return f"({then} if {cond} else {other})"
        if isinstance(node, n.Lookup):
            return self._lookup(node, mode, sn)
        if isinstance(node, n.Call):
            if node.func in MEMORY:
                return self._memory(node, mode, sn)
            return self._function(node, mode, sn)
        raise AssertionError(node)

    def _lookup(self, node: n.Lookup, mode: str, sn: Snippet) -> str:
        table = self.a.spec.tables[node.table]
        keys = [self.expr(key, mode, sn) for key in node.keys]
        key = keys[0] if len(keys) == 1 else f"({', '.join(keys)})"
        name = self.table_names[node.table]
        if table.default is not None:
            return f"{name}.get({key}, {table.default!r})"
        t, k = self.temp("_t"), self.temp("_k")
        return f"({t} if ({t} := {name}.get(({k} := {key}))) is not None else _nokey({self.site(sn, node)}, {k}))"

    def _function(self, node: n.Call, mode: str, sn: Snippet) -> str:
        args = [self.expr(arg, mode, sn) for arg in node.args]
        if node.func in ("abs", "min", "max"):
            return f"_{node.func}({', '.join(args)})"
        if node.func == "sign":
            t = self.temp("_s")
            return f"((({t} := {args[0]}) > 0) - ({t} < 0))"
        # clip, with Lua's order of tests: below low gives low, else above high gives high.
        v, lo, hi = self.temp("_v"), self.temp("_lo"), self.temp("_hi")
        return f"({lo} if ({v} := {args[0]}) < ({lo} := {args[1]}) else ({hi} if {v} > ({hi} := {args[2]}) else {v}))"

    def _memory(self, node: n.Call, mode: str, sn: Snippet) -> str:
        slot = self.a.slots[node.key()]
        i = slot.index
        if mode == FIRST:
            default = self.expr(slot.default, mode, sn) if slot.default is not None else None
            if slot.kind == "prev":
                return default if default is not None else f"_m{i}"
            if slot.kind == "delta":
                return f"(_m{i} - {default if default is not None else f'_m{i}'})"
            return f"_m{i}"
        if slot.kind in ("prev", "initial"):
            return f"s[{i}]"
        if slot.kind == "delta":
            return f"(_m{i} - s[{i}])"
        return f"_p{i}"
