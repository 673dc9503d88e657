"""Candidates: the (type, position) pairs a search still holds, kept and listed.

:class:`Candidates` is the set as the engine filters it: a boolean array per
type over every snapshot position, and the scales each candidate is still
consistent with; :class:`Packed` is the same in a few bytes per candidate, for
undo and the session file. :class:`Candidate` is one listed candidate with its
values at every snapshot, :func:`group_candidates` gathers the rows that read
the same bytes the same way, and :func:`list_groups` is what ``show`` lists.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from retrokit.errors import InvalidArgumentError
from retrokit.host.typecodes import FieldType
from retrokit.ramsearch.ram import RamLayout
from retrokit.ramsearch.scales import ALL_SCALES, MASK_DTYPE, UNPINNED
from retrokit.ramsearch.types import search_type


@dataclass(frozen=True)
class Packed:
    """Candidates kept small, for undo, redo and the session file.

    Attributes:
        bits: The alive flags of every type's positions, one after the other, packed 8 to a byte.
        scales: The scale mask of each alive candidate, in that order.
    """

    bits: np.ndarray
    scales: np.ndarray


class Candidates:
    """Which (type, position) pairs are still candidates, and the scales each is still consistent with.

    Args:
        alive: Per type, a boolean array over positions.
        scale: Per type, an array of scale masks (:mod:`retrokit.ramsearch.scales`; ``UNPINNED`` if none).
    """

    def __init__(self, alive: list[np.ndarray], scale: list[np.ndarray]) -> None:
        self.alive = alive
        self.scale = scale

    @classmethod
    def everything(cls, layout: RamLayout, types: Sequence[FieldType]) -> Candidates:
        """Every position of every type whose bytes fit in a region."""
        alive = [layout.valid(t.width) for t in types]
        return cls(alive, [np.full(layout.size, UNPINNED, dtype=MASK_DTYPE) for _ in types])

    def copy(self) -> Candidates:
        return Candidates([a.copy() for a in self.alive], [s.copy() for s in self.scale])

    def count(self) -> int:
        """How many candidates are left."""
        return int(sum(np.count_nonzero(a) for a in self.alive))

    def pack(self) -> Packed:
        """The candidates in a few bytes per alive one."""
        alive = np.concatenate(self.alive)
        return Packed(np.packbits(alive), np.concatenate(self.scale)[alive])

    @classmethod
    def unpack(cls, packed: Packed, types: int, size: int) -> Candidates:
        """Candidates from :meth:`pack` of ``types`` types over ``size`` positions.

        Raises:
            ValueError: ``packed`` does not hold that many, or its scales do not match its bits.
        """
        if packed.bits.dtype != np.uint8 or len(packed.bits) != -(-types * size // 8):
            raise ValueError(f"expected {types * size} packed candidate bits, found {len(packed.bits) * 8}")
        alive = np.unpackbits(packed.bits, count=types * size).astype(bool)
        if packed.scales.dtype != MASK_DTYPE or len(packed.scales) != np.count_nonzero(alive):
            raise ValueError(f"expected a scale mask per alive candidate, found {len(packed.scales)}")
        if len(packed.scales) and packed.scales.max() > ALL_SCALES:
            raise ValueError("expected scale masks of known scales")
        scale = np.full(types * size, UNPINNED, dtype=MASK_DTYPE)
        scale[alive] = packed.scales
        return cls(list(alive.reshape(types, size)), list(scale.reshape(types, size)))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Candidates) or len(other.alive) != len(self.alive):
            return NotImplemented
        return all(
            np.array_equal(a, b) and np.array_equal(s[a], t[b])
            for a, b, s, t in zip(self.alive, other.alive, self.scale, other.scale)
        )

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True)
class Candidate:
    """One candidate, as ``show`` lists it.

    Attributes:
        address: The console address of its first byte.
        type: Its type code, e.g. ``">u2"``.
        values: Its stored value at each snapshot, oldest first.
        scale: How the screen's value follows from the stored one (``""``: it is the same; ``"-1,/2"``:
            either; see :mod:`retrokit.ramsearch.scales`).
        changes: At how many snapshots its value differed from the one before.
        scales: Every scale still consistent with the value searches (``""`` is the value itself;
            none before a value search).
    """

    address: int
    type: str
    values: tuple[int, ...]
    scale: str = ""
    changes: int = 0
    scales: tuple[str, ...] = ()

    @property
    def low_byte(self) -> int:
        """The address of its least significant byte."""
        return self.address + _low_offset(self.type)


@functools.lru_cache(maxsize=64)
def _low_offset(code: str) -> int:
    """Where a type's least significant byte is, from its first (a listing asks once per candidate)."""
    return search_type(code).significance()[0]


@functools.lru_cache(maxsize=64)
def _width(code: str) -> int:
    return search_type(code).width


def group_candidates(candidates: Sequence[Candidate]) -> list[list[Candidate]]:
    """Group the candidates that are one variable read several ways.

    Candidates with the same least significant byte, scale and values at every
    snapshot are read from the same bytes, in types that agree so far (``|u1``
    and ``<u2`` over a byte followed by a zero, ``>u2`` and ``>u4`` over a
    value whose high word is zero): as Gym Retro's search, count them as one
    find. Each group lists its narrowest type first.
    """
    groups: dict[tuple[int, str, tuple[int, ...]], list[Candidate]] = {}
    for c in candidates:
        groups.setdefault((c.low_byte, c.scale, c.values), []).append(c)
    return [sorted(g, key=lambda c: _width(c.type)) for g in groups.values()]


MAX_LISTED = 100_000  # `show` lists no more: each row is decoded at every snapshot in Python


@dataclass(frozen=True)
class Groups:
    """What ``show`` lists: the candidates gathered into groups that read the same bytes alike.

    Attributes:
        total: How many candidates are left.
        groups: The groups listed, by address, each narrowest type first.
        count: How many groups there are, if every candidate was fetched (else ``None``).
        more: Whether groups beyond those listed exist (or may, when not all were fetched).
    """

    total: int
    groups: list[list[Candidate]]
    count: int | None
    more: bool


def check_listable(total: int, limit: int) -> None:
    """Check ``limit`` candidates (0: all) of ``total`` may be listed.

    Raises:
        InvalidArgumentError: ``limit`` is negative, or all (or over :data:`MAX_LISTED`) are asked of more than that many.
    """
    if not isinstance(limit, int) or limit < 0:
        raise InvalidArgumentError(f"Expected --limit of 0 (all) or more, got {limit!r}.")
    if (not limit or limit > MAX_LISTED) and total > MAX_LISTED:
        raise InvalidArgumentError(
            f"Expected at most {MAX_LISTED:,} candidates to list; found {total:,}. Filter them first, or pass --limit N."
        )


def list_groups(total: int, fetch: Callable[[int | None], list[Candidate]], limit: int, types: int) -> Groups:
    """The first ``limit`` groups of candidates (all when 0), fetching no more candidates than they can hold.

    Args:
        total: How many candidates are left.
        fetch: Lists the candidates by address, at most N of them (all for ``None``).
        limit: How many groups to list; 0 for all.
        types: How many types are searched.

    Raises:
        InvalidArgumentError: See :func:`check_listable`.
    """
    check_listable(total, limit)
    # A group holds at most one candidate per type and start address around its low byte.
    fetched = fetch(limit * types * 8 if limit else None)
    complete = len(fetched) == total
    groups = group_candidates(fetched)
    if limit and not complete:
        groups = groups[:limit]  # the last groups may be cut short, and are not listed
    shown = groups[:limit] if limit else groups
    return Groups(total, shown, len(groups) if complete else None, len(shown) < len(groups) or not complete)
