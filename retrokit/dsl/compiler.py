"""Compile a :class:`ScenarioSpec` into fast step functions.

``compile_spec`` runs the checks (:mod:`~retrokit.dsl.check`,
:mod:`~retrokit.dsl.graph`, :mod:`~retrokit.dsl.typecheck`), generates Python
source (:mod:`~retrokit.dsl.codegen`), and compiles it once with ``compile()``
in a namespace holding only the run-time helpers below: no builtins, no
imports, no attribute access, so a scenario can compute and nothing else.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from retrokit.dsl.check import Checker
from retrokit.dsl.codegen import INT_MAX, INT_MIN, CodeGen, Site
from retrokit.dsl.graph import Graph
from retrokit.dsl.spec import ScenarioSpec, Table
from retrokit.dsl.typecheck import TypeChecker
from retrokit.errors import InvalidArgumentError, ScenarioRuntimeError

StepFunction = Callable[[dict, int, int], tuple[tuple[float, ...], bool]]


class Program:
    """A compiled scenario: generated code plus what its helpers report on.

    Attributes:
        name: The scenario's name.
        players: The number of rewards each step returns.
        fields: The fields the scenario reads.
        slot_count: The length of a Run's state list.
        source: The generated Python source, for reading and debugging.
    """

    def __init__(self, spec: ScenarioSpec, fields: Sequence[str]) -> None:
        analysis = Checker(spec, fields).run()
        Graph(analysis).check_cycles()
        TypeChecker(analysis).run()
        gen = CodeGen(analysis)
        self.name = spec.name
        self.players = max(1, len(spec.rewards))
        self.fields = tuple(analysis.fields)
        self.slot_count = len(analysis.slots)
        self.source = gen.module()
        self._sites = gen.sites
        self._tables = spec.tables
        self._rewards = spec.rewards
        namespace = {
            "__builtins__": {},
            "_abs": abs, "_min": min, "_max": max, "_float": float,
            "_divzero": self._divzero, "_nonfinite": self._nonfinite, "_nokey": self._nokey,
            "_overflow": self._overflow, "_shift": self._shift,
            "_missing": self._missing, "_fail": self._fail,
            "_RuntimeError": ScenarioRuntimeError, "_KeyError": KeyError,
            "_Errors": (ArithmeticError, TypeError, ValueError),
        }
        for name, local in gen.table_names.items():
            namespace[local] = {(k[0] if len(k) == 1 else k): v for k, v in spec.tables[name].entries.items()}
        exec(compile(self.source, f"<scenario {self.name!r}>", "exec"), namespace)  # noqa: S102 - our own generated code
        self._bind = namespace["_bind"]

    def bind(self, state: list, dones: list) -> tuple[StepFunction, StepFunction]:
        """Return ``(first, next)`` step functions working on ``state``, writing players' dones into ``dones``."""
        return self._bind(state, dones)

    # --- run-time errors -------------------------------------------------------------

    def _divzero(self, index: int) -> None:
        site: Site = self._sites[index]
        node = site.node
        divisor = site.snippet.text[node.op_start + len(node.op) : node.end].strip()  # type: ignore[attr-defined]
        raise site.snippet.error(
            ScenarioRuntimeError, node.start, node.end,
            f"scenario {self.name!r}: division by zero: the divisor {divisor} is 0",
        )

    def _overflow(self, index: int, value: object) -> None:
        if not isinstance(value, int):  # a float beyond 2**64 is a float: only integers are 64-bit
            return
        site: Site = self._sites[index]
        raise site.snippet.error(
            ScenarioRuntimeError, site.node.start, site.node.end,
            f"scenario {self.name!r}: expected an integer of 64 bits ({INT_MIN} to {INT_MAX}), got a "
            f"{value.bit_length()}-bit one: scenario integers are 64-bit, and this one overflowed; bound the "
            f"expression, e.g. with clip(), or make it a decimal number with / 1",
        )

    def _shift(self, index: int, count: int) -> None:
        site: Site = self._sites[index]
        node = site.node
        raise site.snippet.error(
            ScenarioRuntimeError, node.start, node.end,
            f"scenario {self.name!r}: expected a shift count from 0 to 63 (integers are 64-bit), got {count}; "
            f"bound the count, e.g. with clip()",
        )

    def _nonfinite(self, player: int, value: float) -> None:
        snippet = self._rewards[player]
        raise snippet.error(
            ScenarioRuntimeError, 0, len(snippet.text),
            f"scenario {self.name!r}: expected the {snippet.role} to be a finite number, got {value}: a value "
            f"overflowed past 1.8e308, or a division or product met NaN; bound the expression, e.g. with clip()",
        )

    def _nokey(self, index: int, key: object) -> None:
        site: Site = self._sites[index]
        table: Table = self._tables[site.node.table]  # type: ignore[attr-defined]
        parts = key if isinstance(key, tuple) else (key,)
        if table.by:
            shown = ", ".join(f"{name}={value}" for name, value in zip(table.by, parts))
        else:
            shown = ", ".join(str(p) for p in parts)
        raise site.snippet.error(
            ScenarioRuntimeError, site.node.start, site.node.end,
            f"scenario {self.name!r}: table {table.name!r} has no entry for {shown}; "
            f"add one (at {table.origin.where()}) or give the table a default",
        )

    def _missing(self, exc: KeyError) -> InvalidArgumentError:
        return InvalidArgumentError(
            f"scenario {self.name!r} reads field {exc.args[0]!r}, and the values given to the step have no such "
            f"key; pass a dict of every field of the game (it reads: {', '.join(self.fields)})"
        )

    def _fail(self, exc: Exception) -> ScenarioRuntimeError:
        return ScenarioRuntimeError(f"scenario {self.name!r}: {type(exc).__name__} while computing a step: {exc}")
