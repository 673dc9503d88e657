"""Candidates: the (type, position) pairs a search still holds, kept and listed.

:class:`Candidates` is the set as the engine filters it: a boolean array per
type over every snapshot position, and the scale each candidate was matched
with; :class:`Packed` is the same in a few bytes per candidate, for undo and
the session file. :func:`list_candidates` lists them as :class:`Candidate`
rows with their values at every snapshot, and :func:`group_candidates`
gathers the rows that read the same bytes the same way.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np

from retrokit.host.typecodes import FieldType, parse_type
from retrokit.ramsearch.ram import RamLayout
from retrokit.ramsearch.scales import SCALES, UNPINNED, scale_label

if TYPE_CHECKING:
    from retrokit.ramsearch.engine import Engine


@dataclass(frozen=True)
class Packed:
    """Candidates kept small, for undo, redo and the session file.

    Attributes:
        bits: The alive flags of every type's positions, one after the other, packed 8 to a byte.
        scales: The scale index of each alive candidate, in that order.
    """

    bits: np.ndarray
    scales: np.ndarray


class Candidates:
    """Which (type, position) pairs are still candidates, and the scale each was matched with.

    Args:
        alive: Per type, a boolean array over positions.
        scale: Per type, an ``int8`` array of scale indices (:data:`~retrokit.ramsearch.scales.UNPINNED` if none).
    """

    def __init__(self, alive: list[np.ndarray], scale: list[np.ndarray]) -> None:
        self.alive = alive
        self.scale = scale

    @classmethod
    def everything(cls, layout: RamLayout, types: Sequence[FieldType]) -> Candidates:
        """Every position of every type whose bytes fit in a region."""
        alive = [layout.valid(t.width) for t in types]
        return cls(alive, [np.full(layout.size, UNPINNED, dtype=np.int8) for _ in types])

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
        if packed.scales.dtype != np.int8 or len(packed.scales) != np.count_nonzero(alive):
            raise ValueError(f"expected a scale per alive candidate, found {len(packed.scales)}")
        if len(packed.scales) and not (UNPINNED <= packed.scales.min() and packed.scales.max() < len(SCALES)):
            raise ValueError("expected scale indices of known scales")
        scale = np.full(types * size, UNPINNED, dtype=np.int8)
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
        scale: How the screen's value follows from the stored one (``""``: it is the same; see
            :mod:`retrokit.ramsearch.scales`).
        changes: At how many snapshots its value differed from the one before.
    """

    address: int
    type: str
    values: tuple[int, ...]
    scale: str = ""
    changes: int = 0

    @property
    def low_byte(self) -> int:
        """The address of its least significant byte."""
        return self.address + parse_type(self.type).significance()[0]


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
    return [sorted(g, key=lambda c: parse_type(c.type).width) for g in groups.values()]


def list_candidates(engine: Engine, limit: int | None = None) -> list[Candidate]:
    """The candidates by address (then simplest type first), at most ``limit`` of them."""
    cands = engine.candidates
    picked = []
    for t, alive in enumerate(cands.alive):
        positions = np.flatnonzero(alive)
        picked.extend((int(p), t) for p in (positions if limit is None else positions[:limit]))
    picked.sort()
    if limit is not None:
        picked = picked[:limit]
    out = []
    addresses = engine.layout.addresses(np.array([p for p, _ in picked], dtype=np.int64)) if picked else []
    for (position, t), address in zip(picked, addresses):
        ftype = engine.types[t]
        values = tuple(ftype.decode(bytes(s[position : position + ftype.width])) for s in engine.snapshots)
        changes = sum(a != b for a, b in pairwise(values))
        out.append(Candidate(int(address), ftype.code, values, scale_label(int(cands.scale[t][position])), changes))
    return out
