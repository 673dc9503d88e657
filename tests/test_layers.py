"""The package's layers: one module over the native host, lazy public names, no upward imports."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "retrokit"
# Each layer may import itself and the layers after it, never one before it. "root" is the package's own
# __init__ (retrokit.make, retrokit.sonic, ...: `import retrokit`); "base" is errors.py, paths.py, datafolder.py, lazy.py and wheel.py
# (the stable-retro wheel's file list), which every layer uses; "native" is the C host's package.
LAYERS = [
    "__main__", "cli", "commands", "studio", "root", "retro", "learning", "benchmark", "testing", "ramsearch", "envs", "movie", "dsl", "data",
    "host", "native", "base",
]
_TOP_MODULES = {
    "__init__": "root", "__main__": "__main__", "cli": "cli", "errors": "base", "paths": "base", "datafolder": "base", "lazy": "base",
    "wheel": "base",
}


def imported_modules(path: Path) -> set[str]:
    """Every retrokit module a source file imports, at any depth (lazy imports included).

    ``from retrokit import make`` is recorded as ``retrokit.make`` (a name of the root package), and
    ``from retrokit import paths`` as ``retrokit.paths``; ``import retrokit`` as ``retrokit``.
    """
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            if node.module != "retrokit":
                found.add(node.module)
            found.update(f"{node.module}.{alias.name}" for alias in node.names)
    return {name for name in found if name.startswith("retrokit")}


def layer_of_module(name: str) -> str:
    """The layer of an imported module: ``retrokit.data.games`` is in data, ``retrokit.make`` in root."""
    parts = name.split(".")
    if len(parts) == 1:
        return "root"
    if (PACKAGE / parts[1]).is_dir():
        return parts[1]
    if (PACKAGE / f"{parts[1]}.py").is_file():
        return _TOP_MODULES[parts[1]]
    return "root"  # a name the root package holds (make, make_vec, sonic, ...)


def layer_of_file(path: Path) -> str:
    """The layer of a source file of the package."""
    parts = path.relative_to(PACKAGE).parts
    return parts[0] if len(parts) > 1 else _TOP_MODULES[path.stem]


SOURCES = sorted(p for p in PACKAGE.rglob("*.py") if "_games" not in p.parts)


def test_exactly_one_module_imports_the_native_host() -> None:
    importers = [
        p.relative_to(PACKAGE).as_posix()
        for p in SOURCES
        if any(m == "retrokit.native._host" or m.startswith("retrokit.native._host.") for m in imported_modules(p))
    ]
    assert importers == ["host/primitives.py"]


def test_every_source_file_is_in_a_layer() -> None:
    assert {layer_of_file(p) for p in SOURCES} == set(LAYERS)


@pytest.mark.parametrize("layer", LAYERS[1:], ids=str)
def test_a_layer_imports_no_layer_above_it(layer: str) -> None:
    above = LAYERS[: LAYERS.index(layer)]
    if layer == "movie":
        above = [name for name in above if name != "envs"]
    offending = {
        f"{p.relative_to(PACKAGE).as_posix()} imports {m}"
        for p in SOURCES
        if layer_of_file(p) == layer
        for m in imported_modules(p)
        if layer_of_module(m) in above
    }
    assert not offending


def test_import_retrokit_loads_no_env_and_no_native_code() -> None:
    heavy = ("retrokit.envs.env", "retrokit.envs.vector", "retrokit.native", "retrokit.host.primitives")
    code = f"import sys, retrokit; print(sorted(m for m in sys.modules if m.startswith({heavy!r})))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


@pytest.mark.parametrize(
    "expression",
    [
        "retrokit.sonic.train_levels()",
        "retrokit.multiplayer.parallel_env",
        "retrokit.movie.read_bk2",
        "retrokit.make",
        "retrokit.make_vec",
        "retrokit.Emulator",
    ],
)
def test_public_names_resolve_after_import_retrokit(expression: str) -> None:
    code = f"import retrokit; {expression}"
    subprocess.run([sys.executable, "-c", code], check=True)


def test_an_unknown_name_is_an_attribute_error() -> None:
    import retrokit

    with pytest.raises(AttributeError, match="no attribute 'sonik'"):
        retrokit.sonik  # noqa: B018
