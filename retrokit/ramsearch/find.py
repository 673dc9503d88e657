"""A field in one command: play what changes it and what keeps it, in turn, until one value is left.

Finding a field by hand is the same loop every time: play something that
changes it and keep the candidates that changed (increased, decreased, or
became a number), play something that does not and keep the unchanged ones,
and repeat. :func:`find_field` runs that loop on a :class:`RamSearch`, from
the game's moment now and the candidates as they are (a filter typed before,
such as ``equal 3``, still counts), until the candidates left are one value
read one or more ways (``|u1``, and the ``>u2`` over it and the zero byte after
it, which reads 768 for 3, are one find), or nothing narrows any more::

    from retrokit.ramsearch import RamSearch
    from retrokit.ramsearch.find import find_field

    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        finding = find_field(search, "RIGHT*200", "_*130", "decreases")
        print(finding.candidate)          # the lives: address 0xFF002B, type |u1

Each script and filter is an ordinary snapshot and filter of the search, so
``history`` lists them and ``undo`` takes them back one at a time.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from retrokit.data.script import parse_script, script_frames
from retrokit.errors import InvalidArgumentError, did_you_mean, shown
from retrokit.ramsearch.candidates import Candidate, group_candidates, list_groups
from retrokit.ramsearch.filters import check_filter
from retrokit.ramsearch.types import search_type

if TYPE_CHECKING:
    from retrokit.ramsearch.search import RamSearch

#: Each kind of change, and the filter that keeps it after the first script.
KINDS = {"increases": "increased", "decreases": "decreased", "changes": "changed", "becomes": "equal"}
MAX_ROUNDS = 10  # each round two snapshots of the RAM; a field that ten rounds cannot single out needs other play
SHOWN = 10  # groups a finding lists when more than one is left
MAX_ALIASES = 512  # more candidates than this are never one value read in every type and order around one byte


@dataclass
class Finding:
    """What :func:`find_field` left.

    Attributes:
        count: How many candidates are left.
        groups: The groups of candidates left, by address (at most :data:`SHOWN`), each narrowest type first.
        steps: Each filter applied, as ``history`` names it, with the counts before and after.
        rounds: How many rounds were played.
        reason: Why it stopped, in words (one value left, none left, nothing narrowed, out of rounds).
        found: Whether one value is left: then the first group holds its narrowest reading first.
        frames: How many frames the scripts played.
    """

    count: int
    groups: list[list[Candidate]] = field(default_factory=list)
    steps: list[str] = field(default_factory=list)
    rounds: int = 0
    reason: str = ""

    found: bool = False
    frames: int = 0

    @property
    def candidate(self) -> Candidate | None:
        """The one value found (its narrowest reading), or ``None`` if more than one value is left."""
        return self.groups[0][0] if self.found else None


def check_kind(kind: str, value: int | None) -> str:
    """The filter a kind of change keeps after the first script.

    Raises:
        InvalidArgumentError: The kind is unknown, or ``becomes`` lacks its number (or another kind has one).
    """
    if kind not in KINDS:
        raise InvalidArgumentError(
            f"Expected a kind of change: {', '.join(KINDS)} (becomes N); got {shown(kind)}." + did_you_mean(str(kind), KINDS)
        )
    if (kind == "becomes") != (value is not None):
        raise InvalidArgumentError(
            "Expected a number with 'becomes' (becomes 0: the value it takes), and none with another kind; "
            f"got {kind!r} with {'no number' if value is None else value}."
        )
    return KINDS[kind]


def find_field(
    search: RamSearch,
    changes: str,
    keeps: str,
    kind: str = "changes",
    value: int | None = None,
    *,
    rounds: int = MAX_ROUNDS,
    progress: Callable[[str], object] | None = None,
) -> Finding:
    """Play ``changes`` and ``keeps`` in turn, filtering after each, until one value is left.

    Args:
        search: The search, at the game's moment to start from.
        changes: A script (:mod:`retrokit.data.script`) that changes the field.
        keeps: A script that leaves it as it is.
        kind: How ``changes`` changes it: ``increases``, ``decreases``, ``changes`` or ``becomes`` (``value``).
        value: The number it becomes, with ``becomes``.
        rounds: The most rounds (a script and a filter each) to play.
        progress: Called with each filter's line as it is applied.

    Raises:
        InvalidArgumentError: A script or the kind is malformed (checked before anything plays).
    """
    op = check_kind(kind, value)
    check_filter(op, value)  # a number no filter takes is refused before anything plays
    frames = {script: script_frames(parse_script(script, search.buttons)) for script in (changes, keeps)}
    if not isinstance(rounds, int) or isinstance(rounds, bool) or not 1 <= rounds <= MAX_ROUNDS:
        raise InvalidArgumentError(f"Expected from 1 to {MAX_ROUNDS} rounds; got {shown(rounds)}.")
    finding = Finding(search.count)
    for finding.rounds in range(1, rounds + 1):
        start = search.count
        for script, filter_op, filter_value in ((changes, op, value), (keeps, "unchanged", None)):
            search.run_script(script)
            finding.frames += frames[script]
            before = search.count
            search.filter(filter_op, filter_value)
            finding.steps.append(f"{search.labels[-1]}; {search.history[-1]}: {before:,} -> {search.count:,} candidates")
            if progress is not None:
                progress(finding.steps[-1])
            if not search.count:  # the game stopped following the scripts (out of lives, say): keep what was left
                search.undo()
                return _left(search, finding, "the last filter left no candidate, and was undone")
            if _one_value(search, finding):
                return finding
        if search.count == start:
            return _left(search, finding, "a whole round narrowed nothing: the candidates left all follow both "
                         "scripts alike; play something that tells them apart")
    return _left(search, finding, f"{rounds} rounds played, and more than one value is left")


def _left(search: RamSearch, finding: Finding, reason: str) -> Finding:
    """``finding``, stopped for ``reason``: one value if that is what is left, else the first groups listed."""
    if not _one_value(search, finding):
        finding.groups = list_groups(search.count, search.candidates, SHOWN, len(search.types)).groups
        finding.reason = reason
    return finding


def _one_value(search: RamSearch, finding: Finding) -> bool:
    """Whether the candidates left are one value read several ways; if so, it is put into ``finding``.

    The value is the simplest reading left: the narrowest type, then the values spanning least (``<u2`` over
    a byte and the zero before it reads the byte times 256), then the type searched first, then the lowest
    address. Another candidate is the same value when it is a copy of it (its values differ from the value's
    by the same number at every snapshot: a HUD's digit, a C stack's copy, a sprite's position on a screen
    that has not scrolled), or when it reads a byte of the value or of a copy and changed at the same
    snapshots (the byte read with the constant bytes around it: ``>u2`` over lives and the zero after them
    reads 768 for 3).
    """
    finding.count = search.count
    if not finding.count or finding.count > MAX_ALIASES:
        return False
    candidates = search.candidates()
    order = {code: index for index, code in enumerate(search.types)}
    width = {c.type: search_type(c.type).width for c in candidates}
    best = min(candidates, key=lambda c: (width[c.type], max(c.values) - min(c.values), order[c.type], c.address))
    copies = [c for c in candidates if len({v - b for v, b in zip(c.values, best.values)}) == 1]
    bytes_of = {a for c in copies for a in range(c.address, c.address + width[c.type])}
    moves = _moves(best)
    if not all(
        c in copies or _moves(c) == moves and not bytes_of.isdisjoint(range(c.address, c.address + width[c.type]))
        for c in candidates
    ):
        return False
    groups = group_candidates(candidates)
    finding.groups = sorted(groups, key=lambda g: best not in g)[:SHOWN]  # its group first
    finding.groups[0].sort(key=lambda c: c is not best)
    others = sorted({c.address for c in copies if c.values == best.values} - {best.address})  # the exact ones
    finding.reason = (
        "one value is left"
        + (f", read {len(candidates)} ways" if len(candidates) > 1 else "")
        + (f"; copies at {', '.join(search.layout.format(a) for a in others)}" if others else "")
    )
    finding.found = True
    return True


def _moves(candidate: Candidate) -> tuple[bool, ...]:
    """At which snapshots a candidate's value changed."""
    return tuple(a != b for a, b in zip(candidate.values, candidate.values[1:]))
