"""stable-retro's names that ``retrokit.retro`` does not have: asking for one says, in one line, what to use instead."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any


def missing_names(module: str, elsewhere: Mapping[str, str]) -> Callable[[str], Any]:
    """A module ``__getattr__`` that names retrokit's counterpart of each of stable-retro's names in ``elsewhere``."""

    def __getattr__(name: str) -> Any:
        if name in elsewhere:
            raise AttributeError(f"{module} has no {name} (stable-retro's); use {elsewhere[name]}.")
        raise AttributeError(f"module {module!r} has no attribute {name!r}")

    return __getattr__
