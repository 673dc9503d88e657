"""The order in which a scenario's definitions and memory slots are computed.

A step computes, in dependency order, every definition that the outputs need
and every memory call's argument (the value the slot will remember), then the
outputs, then writes the slots. Two modes differ in what a memory call needs:

- ``FIRST`` (reset, or the first step without a reset) has no past, so
  ``prev(x)`` and ``initial(x)`` are ``x`` itself, ``peak(x)`` is ``x`` and
  ``delta(x)`` is 0; ``prev(x, d)`` is ``d`` and ``delta(x, d)`` is ``x - d``.
- ``NEXT`` (every later step) reads ``prev`` and ``initial`` from the slots, and
  ``delta`` and ``peak`` from the slot and the argument's current value.

A definition may use its own earlier value only through ``prev(x, d)``: in
``FIRST`` mode that is ``d``, so no definition needs itself. Any other cycle
is an error.
"""

from __future__ import annotations

from collections.abc import Callable

from retrokit.dsl import nodes as n
from retrokit.dsl.check import MEMORY, Analysis, Slot
from retrokit.errors import ScenarioCompileError

FIRST, NEXT = "first", "next"

Item = tuple[str, object]  # ("def", name) or ("slot", index)


def _memory(node: n.Node, analysis: Analysis) -> Slot | None:
    if isinstance(node, n.Call) and node.func in MEMORY:
        return analysis.slots[node.key()]
    return None


def deps(node: n.Node, mode: str, analysis: Analysis) -> set[Item]:
    """Items whose value ``node`` reads now, in ``mode``."""
    found: set[Item] = set()
    stack = [node]
    while stack:
        current = stack.pop()
        slot = _memory(current, analysis)
        if slot is not None:
            if mode == FIRST:
                if slot.default is not None:
                    stack.append(slot.default)
                if not (slot.kind == "prev" and slot.default is not None):
                    found.add(("slot", slot.index))
            elif slot.kind in ("delta", "peak"):
                found.add(("slot", slot.index))
            continue
        if isinstance(current, n.Name) and current.id in analysis.defines:  # never a counter: reserved
            found.add(("def", current.id))
        stack.extend(current.children())
    return found


def needs(node: n.Node, mode: str, analysis: Analysis) -> set[Item]:
    """Items that must be computed in ``mode`` because of ``node``: its deps and its slots' arguments."""
    found = deps(node, mode, analysis)
    stack = [node]
    while stack:
        current = stack.pop()
        slot = _memory(current, analysis)
        if slot is not None:
            if mode == FIRST or slot.kind != "initial":
                found.add(("slot", slot.index))
            if mode == FIRST and slot.default is not None:
                stack.append(slot.default)
            continue
        stack.extend(current.children())
    return found


class Graph:
    """Dependencies between a scenario's definitions and slots."""

    def __init__(self, analysis: Analysis) -> None:
        self.a = analysis
        self._slots = {slot.index: slot for slot in analysis.slots.values()}

    def expression(self, item: Item) -> n.Node:
        """The expression an item computes."""
        kind, key = item
        return self.a.defines[key] if kind == "def" else self._slots[key].arg  # type: ignore[index]

    def roots(self) -> list[n.Node]:
        """The outputs: rewards, done, then the players' dones."""
        return [*self.a.rewards, *([self.a.done] if self.a.done is not None else []), *self.a.dones]

    def check_cycles(self) -> None:
        """Raise ScenarioCompileError if something needs itself at reset."""
        items: list[Item] = [("def", name) for name in self.a.defines]
        items += [("slot", index) for index in self._slots]
        self._postorder(items, FIRST, on_cycle=self._cycle_error)

    def order(self, mode: str) -> list[Item]:
        """The items to compute in ``mode``, each after the items it reads."""
        live: set[Item] = set()
        stack = [item for root in self.roots() for item in needs(root, mode, self.a)]
        while stack:
            item = stack.pop()
            if item not in live:
                live.add(item)
                stack.extend(needs(self.expression(item), mode, self.a))
        return self._postorder(sorted(live, key=repr), mode)

    def definition_order(self) -> list[str]:
        """Every definition, each after the definitions it reads at reset (no cycles: see check_cycles)."""
        items: list[Item] = [("def", name) for name in self.a.defines]
        return [key for kind, key in self._postorder(items, FIRST) if kind == "def"]  # type: ignore[misc]

    def _postorder(
        self, items: list[Item], mode: str, on_cycle: Callable[[list[Item]], None] | None = None
    ) -> list[Item]:
        """Depth-first post-order from ``items`` over what each reads in ``mode``.

        Iterative, so a chain of thousands of definitions needs no deep Python
        stack. ``on_cycle`` gets the path of any item met again while it is
        still being visited (a cycle), ending with that item.
        """
        ordered: list[Item] = []
        state: dict[Item, int] = {}  # 1: on the path, 2: done
        for root in items:
            if root in state:
                continue
            state[root] = 1
            path = [root]
            pending = [iter(sorted(deps(self.expression(root), mode, self.a), key=repr))]
            while pending:
                dep = next(pending[-1], None)
                if dep is None:
                    pending.pop()
                    done = path.pop()
                    state[done] = 2
                    ordered.append(done)
                elif state.get(dep) == 1:
                    if on_cycle is not None:
                        on_cycle(path[path.index(dep):] + [dep])
                elif dep not in state:
                    state[dep] = 1
                    path.append(dep)
                    pending.append(iter(sorted(deps(self.expression(dep), mode, self.a), key=repr)))
        return ordered

    def _label(self, item: Item) -> str:
        kind, key = item
        if kind == "def":
            return str(key)
        slot = self._slots[key]  # type: ignore[index]
        return f"{slot.kind}({slot.arg.key()})"

    def _cycle_error(self, cycle: list[Item]) -> None:
        first = next((item for item in cycle if item[0] == "def"), cycle[0])
        start = cycle.index(first)
        cycle = cycle[start:-1] + cycle[:start] + [first]
        chain = " -> ".join(self._label(item) for item in cycle)
        target = cycle[1]
        if first[0] == "def":
            snippet = self.a.spec.defines[first[1]]  # type: ignore[index]
        else:
            snippet = self._slots[first[1]].snippet  # type: ignore[index]
        node = self._reference(self.expression(first), target) or self.expression(first)
        name = self._label(first)
        raise snippet.error(
            ScenarioCompileError, node.start, node.end,
            f"{name!r} depends on itself: {chain}. A definition can use its own earlier value "
            f"only through prev(name, value_at_reset), e.g. prev({name}, 0)",
        )

    def _reference(self, root: n.Node, target: Item) -> n.Node | None:
        """The smallest name or call under ``root`` that reads ``target`` now."""
        found = [
            node for node in n.walk(root)
            if isinstance(node, (n.Name, n.Call)) and target in deps(node, FIRST, self.a)
        ]
        return min(found, key=lambda node: node.end - node.start, default=None)
