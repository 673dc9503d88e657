"""RAM search: find a game's variables in RAM and write them into its game.yaml.

- :class:`RamSearch` (:mod:`.search`): the search on a running game, its moves and its session file.
- :mod:`.keeping`: what the search writes out: the movie of the inputs played, the game's state, a field.
- :mod:`.engine`: snapshots and candidates, narrowed by filters, with undo and redo.
- :mod:`.filters`: the operations and references a filter compares with.
- :mod:`.candidates`: the candidate set, packed for undo, and grouped for ``show``.
- :mod:`.types`: every type interpretation of a snapshot, decoded at once.
- :mod:`.scales`: the scaled matches of a value search.
- :mod:`.ram`: the RAM regions as console-order bytes, and console addresses.
- :mod:`.script`: input scripts (taps, holds and waits in one line).
- :mod:`.session`: the session file, and when a new one may replace it.
- :mod:`.gamefile`: writing a field into a game.yaml, keeping its layout.

See ``docs/ramsearch.md``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from retrokit.lazy import lazy_names

__all__ = ["DEFAULT_SESSION", "OPS", "SEARCH_TYPES", "Candidate", "RamSearch", "group_candidates", "list_groups"]

if TYPE_CHECKING:
    from retrokit.ramsearch.candidates import Candidate, group_candidates, list_groups
    from retrokit.ramsearch.filters import OPS
    from retrokit.ramsearch.search import RamSearch
    from retrokit.ramsearch.session import DEFAULT_SESSION
    from retrokit.ramsearch.types import SEARCH_TYPES

# Its names and submodules, on first use, so that `retrokit ramsearch --help` (which imports .filters) does
# not import the search, numpy and the emulator.
__getattr__ = lazy_names(
    __name__,
    {
        "Candidate": "retrokit.ramsearch.candidates",
        "group_candidates": "retrokit.ramsearch.candidates",
        "list_groups": "retrokit.ramsearch.candidates",
        "OPS": "retrokit.ramsearch.filters",
        "RamSearch": "retrokit.ramsearch.search",
        "DEFAULT_SESSION": "retrokit.ramsearch.session",
        "SEARCH_TYPES": "retrokit.ramsearch.types",
    },
)
