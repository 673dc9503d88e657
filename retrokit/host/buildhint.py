"""The one line that says ``retrokit build-core`` makes a system's env faster, and by how much.

The figure is the system descriptor's ``build_core`` (systems.yaml), measured by
``tools/bench_built_core.py``. The line is shown only while the wheel's core is
the one found: a user who built the core, or who chose a core of their own
(``RETROKIT_CORES``), never sees it.
"""

from __future__ import annotations

from collections.abc import Iterable

from retrokit.errors import CoreNotFoundError
from retrokit.host.build import RECIPES
from retrokit.host.cores import locate_core
from retrokit.host.systems import System, get_system


def speedup_text(system: System) -> str:
    """``"2.6x faster"``, or ``""`` when the descriptor holds no figure."""
    return "" if system.build_speedup is None else f"{system.build_speedup:.1f}x faster"


def build_hint(system: System | str) -> str:
    """The line for one system, or ``""`` when it has no figure, no recipe, or its wheel core is not the one used."""
    system = get_system(system)
    if system.build_speedup is None or system.core not in RECIPES:
        return ""
    try:
        if locate_core(system.core).origin != "wheel":
            return ""
    except CoreNotFoundError:
        return ""
    return (
        f"Tip: {system.name} envs step {speedup_text(system)} on a core built from stable-retro's source: "
        f"retrokit build-core {system.core} (a C compiler and make; retrokit docs cores)."
    )


def build_hints(systems: Iterable[System | str]) -> list[str]:
    """The lines for these systems, each once, in order; empty when every one runs its fastest core."""
    lines = (build_hint(system) for system in dict.fromkeys(get_system(s).name for s in systems))
    return [line for line in lines if line]
