"""Names of a package imported on first use (PEP 562), so every documented dotted path works after ``import retrokit``.

The docs write ``retrokit.envs.sonic.make`` and ``retrokit.dsl.convert_scenario_json``;
users type them after a plain ``import retrokit``. Each package's
``__init__`` sets ``__getattr__ = lazy_names(__name__, ...)``: a submodule,
or a name a package re-exports, is imported the first time it is looked up,
and not before, so ``import retrokit`` (and ``retrokit --help``) stays fast.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from collections.abc import Callable, Mapping
from typing import Any


def lazy_names(
    package: str, attributes: Mapping[str, str] | None = None, modules: Mapping[str, str] | None = None
) -> Callable[[str], Any]:
    """A module ``__getattr__`` for ``package``: its submodules, ``attributes`` and ``modules``, imported on first use.

    Args:
        package: The package's name (its ``__name__``).
        attributes: Names the package re-exports, each with the module that defines it.
        modules: Other names for modules elsewhere (``retrokit.sonic`` is ``retrokit.envs.sonic``).
    """
    exported, aliases = dict(attributes or {}), dict(modules or {})

    def __getattr__(name: str) -> Any:
        if name in exported:
            value = getattr(importlib.import_module(exported[name]), name)
        elif name in aliases:
            value = importlib.import_module(aliases[name])
        elif not name.startswith("__") and _is_submodule(f"{package}.{name}"):
            value = importlib.import_module(f"{package}.{name}")
        else:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        setattr(sys.modules[package], name, value)  # later lookups skip this function
        return value

    return __getattr__


def _is_submodule(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False
