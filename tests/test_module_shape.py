"""The shape of retrokit's own code: no module over 500 lines, no import circle between modules.

Both are rules of the house that drift back one change at a time, so they are
checked on every run rather than by eye.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "retrokit"
MAX_LINES = 500
OWN_SUFFIXES = (".py", ".c", ".h", ".js")
# Being split on another branch of issue 32 (retrokit/native is its helper's): drop the entry once that is merged.
def own_files() -> list[Path]:
    """Every source file of ours in the package: Python, C and JavaScript, without what is vendored."""
    return sorted(
        path
        for path in PACKAGE.rglob("*")
        if path.suffix in OWN_SUFFIXES and "vendor" not in path.relative_to(PACKAGE).parts
    )


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules() -> dict[str, Path]:
    return {module_name(path): path for path in PACKAGE.rglob("*.py")}


def _type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def imported(name: str, path: Path, known: dict[str, Path]) -> set[str]:
    """The retrokit modules ``name`` imports when it runs: at module level or inside a function.

    An import under ``if TYPE_CHECKING:`` never runs, so it does not count;
    one inside a function does, as it runs each time the function is called.
    ``from retrokit.a import b`` names module ``retrokit.a.b`` if there is one, else ``retrokit.a``.
    """
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: set[str] = set()

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and _type_checking(node):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            for alias in node.names:
                found.add(f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else base)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(ast.parse(path.read_text(encoding="utf-8"), str(path)))
    return {target for target in found if target in known and target != name}


def import_cycles() -> list[list[str]]:
    """The import circles between retrokit's modules, each as the modules around it."""
    known = modules()
    graph = {name: sorted(imported(name, path, known)) for name, path in known.items()}
    cycles: list[list[str]] = []
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    stack: list[str] = []

    def walk(node: str) -> None:
        state[node] = 1
        stack.append(node)
        for target in graph[node]:
            if state.get(target) == 1:
                cycles.append([*stack[stack.index(target) :], target])
            elif target not in state:
                walk(target)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            walk(node)
    return cycles


def test_no_module_of_ours_is_over_500_lines() -> None:
    files = own_files()
    assert len(files) > 100 and any(p.suffix == ".c" for p in files) and any(p.suffix == ".js" for p in files)
    long = {
        name: n
        for p in files
        if (n := len(p.read_bytes().splitlines())) > MAX_LINES
        and (name := str(p.relative_to(PACKAGE.parent)))
    }
    assert not long, f"over {MAX_LINES} lines (split each along a seam it has): {long}"


def test_no_import_circle_between_modules() -> None:
    cycles = import_cycles()
    assert not cycles, "import circles: " + "; ".join(" -> ".join(cycle) for cycle in cycles)


@pytest.mark.parametrize(
    ("source", "circle"),
    [
        ("from retrokit.b import thing\n", True),
        ("def later():\n    from retrokit import b\n", True),  # a function-level import closes a circle too
        ("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from retrokit.b import thing\n", False),
        ("import retrokit.c\n", False),
    ],
    ids=["module-level", "function-level", "type-checking-only", "no-circle"],
)
def test_the_circle_finder_sees_what_runs(tmp_path, monkeypatch, source: str, circle: bool) -> None:
    """The finder itself, on a package of three modules where b imports a and a imports whatever ``source`` says."""
    package = tmp_path / "retrokit"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "a.py").write_text(source)
    (package / "b.py").write_text("from retrokit import a\n")
    (package / "c.py").write_text("")
    monkeypatch.setattr(sys.modules[__name__], "PACKAGE", package)
    assert bool(import_cycles()) is circle
