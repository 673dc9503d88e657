"""The search engine: candidates over snapshots, narrowed by filters, with undo and redo.

A candidate is a type and a snapshot position (the value of that type that
starts there), with every scale its value searches are consistent with
(:mod:`retrokit.ramsearch.scales`). Candidates are kept as one boolean array
per type over every position, so a filter is a few numpy comparisons over the
type's decoded values (:mod:`retrokit.ramsearch.types`); once few candidates
are left, only their positions are compared.

The filters themselves are described in :mod:`retrokit.ramsearch.filters`;
the candidate set in :mod:`retrokit.ramsearch.candidates`.
"""

from __future__ import annotations

from collections.abc import Sequence
from itertools import pairwise

import numpy as np

from retrokit.errors import InvalidArgumentError, RamSearchError
from retrokit.host.typecodes import FieldType
from retrokit.ramsearch.candidates import Candidate, Candidates, Packed
from retrokit.ramsearch.filters import CHANGES, COMPARISONS, Filter, check_filter
from retrokit.ramsearch.ram import RamLayout
from retrokit.ramsearch.scales import MASK_DTYPE, SCALES, UNPINNED, scale_label, scale_labels
from retrokit.ramsearch.types import decode_all, value_dtype

# Scales that divide: a value shown through one is defined only where the division is exact.
_DIVIDING = sum(1 << index for index, scale in enumerate(SCALES) if scale.div != 1)

_SPARSE = 8  # compare only the candidates' positions once fewer than 1 in 8 positions are left
_DECODED_KEPT = 4  # decoded snapshots kept for the next filter
_UNPACKED_KEPT = 4  # the newest steps of the history kept as they are (4 MiB each for 64 KiB), the rest packed


class Engine:
    """Snapshots and candidates of one RAM search.

    Args:
        layout: The RAM regions.
        types: The types searched.
    """

    def __init__(self, layout: RamLayout, types: Sequence[FieldType]) -> None:
        self.layout = layout
        self.types = tuple(types)
        self.snapshots: list[np.ndarray] = []
        self.candidates = Candidates.everything(layout, self.types)
        self.history: list[tuple[str, Candidates | Packed]] = []  # (filter, the candidates before it)
        self.redo_stack: list[tuple[str, Candidates | Packed]] = []  # (filter, the candidates after it)
        self._decoded: dict[int, list[np.ndarray]] = {}
        self._counts: list[np.ndarray] = []  # change counts, while a filter on them runs

    # --- snapshots --------------------------------------------------------------------------

    def add_snapshot(self, data: np.ndarray) -> int:
        """Add a snapshot (console-order bytes); return its index."""
        data = np.ascontiguousarray(data, dtype=np.uint8)
        if data.shape != (self.layout.size,):
            raise InvalidArgumentError(f"Expected a snapshot of {self.layout.size} bytes, got shape {data.shape}.")
        self.snapshots.append(data)
        return len(self.snapshots) - 1

    def decoded(self, index: int) -> list[np.ndarray]:
        """Snapshot ``index`` decoded as every type (a few are cached)."""
        index %= len(self.snapshots)
        if index not in self._decoded:
            while len(self._decoded) >= _DECODED_KEPT:
                del self._decoded[next(iter(self._decoded))]
            self._decoded[index] = decode_all(self.snapshots[index], self.types)
        return self._decoded[index]

    def change_counts(self) -> list[np.ndarray]:
        """Per type, at how many snapshots the value at each position differed from the one before.

        Snapshots are decoded in order, two at a time, whatever their number.
        """
        counts = [np.zeros(self.layout.size, dtype=np.int32) for _ in self.types]
        for k in range(1, len(self.snapshots)):
            before, after = self.decoded(k - 1), self.decoded(k)
            for count, old, new in zip(counts, before, after):
                count += old != new
        return counts

    # --- filtering ----------------------------------------------------------------------------

    def filter(self, op: str, value: int | None = None, than: str | int | None = None) -> int:
        """Keep the candidates that pass a filter; return how many are left.

        Raises:
            InvalidArgumentError: The filter is malformed, or its address is outside RAM.
            RamSearchError: The filter compares snapshots and there are not two yet.
        """
        spec = check_filter(op, value, than)
        if not self.snapshots:
            raise RamSearchError("Expected a snapshot to filter; found none. Take one first (RamSearch.snapshot).")
        if spec.than in ("previous", "first", "changes") and len(self.snapshots) < 2:
            raise RamSearchError(
                f"Expected two snapshots to compare for '{spec.describe()}'; found 1. Move the game on first, "
                "e.g. retrokit ramsearch run --frames 60, or compare with a number: filter equal N."
            )
        if spec.snapshot is not None and not 0 <= spec.snapshot < len(self.snapshots) - 1:
            raise RamSearchError(
                f"Expected --than a snapshot taken before the newest, 0 to {len(self.snapshots) - 2}; got "
                f"{spec.snapshot} of {len(self.snapshots)} snapshot(s). `retrokit ramsearch history` lists them."
                if len(self.snapshots) > 1
                else "Expected an earlier snapshot to compare with; found only snapshot 0. Move the game on first, "
                "e.g. retrokit ramsearch run --frames 60."
            )
        if isinstance(spec.than, int):
            self.layout.position(spec.than)  # outside RAM: a clear error now
        before = Candidates(list(self.candidates.alive), list(self.candidates.scale))  # filters replace arrays
        self._counts = self.change_counts() if spec.than == "changes" else []
        for t in range(len(self.types)):
            self._filter_type(t, spec)
        self._counts = []
        self.history.append((spec.describe(self.layout), before))
        self.redo_stack.clear()
        for index in range(max(0, len(self.history) - _UNPACKED_KEPT)):
            label, entry = self.history[index]
            if isinstance(entry, Candidates):
                self.history[index] = (label, entry.pack())
        return self.candidates.count()

    def _restore(self, entry: Candidates | Packed) -> Candidates:
        return entry if isinstance(entry, Candidates) else Candidates.unpack(entry, len(self.types), self.layout.size)

    def _filter_type(self, t: int, spec: Filter) -> None:
        # New arrays replace the type's old ones, never changing them: the
        # history holds the old ones as they were, without a copy.
        alive, scales = self.candidates.alive[t], self.candidates.scale[t]
        left = np.count_nonzero(alive)
        if not left:
            return
        if left * _SPARSE < len(alive):  # few left: compare only their positions
            positions = np.flatnonzero(alive)

            def pick(a: np.ndarray) -> np.ndarray:
                return a[positions]

            keep, masks = self._compare(t, spec, pick(self.decoded(-1)[t]), scales[positions], pick)
            kept = alive.copy()
            kept[positions] = keep
            self.candidates.alive[t] = kept
            if masks is not None:
                scales = self.candidates.scale[t] = scales.copy()
                scales[positions] = masks
        else:
            keep, masks = self._compare(t, spec, self.decoded(-1)[t], scales, lambda a: a)
            self.candidates.alive[t] = alive & keep
            if masks is not None:
                self.candidates.scale[t] = masks

    def _compare(
        self, t: int, spec: Filter, cur: np.ndarray, mask: np.ndarray, pick
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """Which candidates pass, and their scale masks after it (``None``: unchanged)."""
        ftype = self.types[t]
        if spec.than is None and spec.op == "equal":
            return _value_search(ftype, cur, mask, spec.value)
        if spec.than == "changes":
            return COMPARISONS[spec.op](pick(self._counts[t]), spec.value), None
        reference = spec.reference_snapshot(len(self.snapshots))
        if reference is not None:
            ref = pick(self.decoded(reference)[t])
            if spec.op != "changed-by":
                # shown = stored * mult / div + bias rises with stored: a comparison of two values
                # shown through one scale is that of the stored ones, where both divide exactly.
                result = COMPARISONS[CHANGES.get(spec.op, spec.op)](cur, ref)
                return _narrow(result, mask, lambda index: _exact(index, cur) & _exact(index, ref))
        elif isinstance(spec.than, int):  # another address: its stored value in the newest snapshot
            try:
                position = self.layout.position(spec.than, ftype.width)
            except InvalidArgumentError:
                return np.zeros(len(cur), dtype=bool), None
            ref = self.decoded(-1)[t][position]
        else:
            ref = spec.value

        def passes(index: int | None) -> np.ndarray:
            """The filter read through scale ``index`` (``None``: the stored values themselves)."""
            if index is None:
                shown, here = cur, ref
            else:
                shown, ok = SCALES[index].shown(cur)
                here = ref
                if reference is not None:  # both sides are shown through the scale
                    here, ref_ok = SCALES[index].shown(ref)
                    ok &= ref_ok
            if spec.op == "changed-by":
                result = _changed_by(shown, here, spec.value)
            else:
                result = COMPARISONS[CHANGES.get(spec.op, spec.op)](shown, here)
            return result if index is None else result & ok

        return _per_scale(passes, mask)

    # --- undo and redo ---------------------------------------------------------------------

    def undo(self) -> str:
        """Undo the last filter; return its description.

        Raises:
            RamSearchError: No filter to undo.
        """
        if not self.history:
            raise RamSearchError("Expected a filter to undo; found none. Filters are undone newest first.")
        label, before = self.history.pop()
        self.redo_stack.append((label, self.candidates))
        self.candidates = self._restore(before)
        return label

    def redo(self) -> str:
        """Apply the last undone filter again; return its description.

        Raises:
            RamSearchError: Nothing was undone since the last filter.
        """
        if not self.redo_stack:
            raise RamSearchError("Expected an undone filter to redo; found none (a new filter clears what undo kept).")
        label, after = self.redo_stack.pop()
        self.history.append((label, self.candidates))
        self.candidates = self._restore(after)
        return label


def _changed_by(cur: np.ndarray, ref: np.ndarray | int, by: int) -> np.ndarray:
    """Where ``cur - ref == by``, computed in the arrays' own dtype.

    The difference wraps modulo ``2**bits``, so equal wrapped differences are
    told apart by the sign of the true one: ``cur >= ref`` exactly when it is
    ``by >= 0``. That saves widening every array to int64.
    """
    if cur.dtype.itemsize == 8 or not isinstance(ref, np.ndarray) or ref.dtype != cur.dtype:
        return np.subtract(cur, ref, dtype=np.int64) == by
    bits = 8 * cur.dtype.itemsize
    if not -(1 << bits) < by < 1 << bits:
        return np.zeros(len(cur), dtype=bool)
    unsigned = np.dtype(f"u{cur.dtype.itemsize}")
    wrapped = cur.view(unsigned) - ref.view(unsigned)
    result = wrapped == unsigned.type(by % (1 << bits))
    result &= (cur >= ref) if by >= 0 else (cur < ref)
    return result


def _exact(index: int, stored: np.ndarray) -> np.ndarray | bool:
    """Where a scale's division of stored values is exact (everywhere for a scale that does not divide)."""
    scale = SCALES[index]
    return True if scale.div == 1 else stored.astype(np.int64) * scale.mult % scale.div == 0


def _narrow(result: np.ndarray, mask: np.ndarray, defined) -> tuple[np.ndarray, np.ndarray | None]:
    """A result that holds alike through every scale, where ``defined(index)`` says the scale reads both values.

    Unpinned candidates keep ``result``; a pinned one keeps the scales that
    pass, and stays while one does.
    """
    if not np.count_nonzero(mask):  # UNPINNED is 0: nothing pinned (a fresh search)
        return result, None
    pinned = mask != UNPINNED
    masks = np.where(result, mask, MASK_DTYPE.type(0))
    for index in _bits_in(mask, _DIVIDING):
        bit = MASK_DTYPE.type(1 << index)
        masks[~np.asarray(defined(index), dtype=bool) & (masks & bit != 0)] &= ~bit
    return result & ~pinned | (masks != 0), np.where(pinned, masks, mask)


def _per_scale(passes, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """A filter that reads differently through each scale: unpinned candidates as stored, pinned ones per scale."""
    if not np.count_nonzero(mask):
        return passes(None), None
    pinned = mask != UNPINNED
    keep = passes(None) & ~pinned if not pinned.all() else np.zeros(len(mask), dtype=bool)
    masks = np.zeros(len(mask), dtype=MASK_DTYPE)
    for index in _bits_in(mask):
        bit = MASK_DTYPE.type(1 << index)
        masks[passes(index) & (mask & bit != 0)] |= bit
    return keep | (masks != 0), np.where(pinned, masks, mask)


def _bits_in(mask: np.ndarray, among: int = -1) -> list[int]:
    """The scale indices set in any of ``mask`` (and in ``among``)."""
    union = int(np.bitwise_or.reduce(mask)) if len(mask) else 0
    union &= among
    return [index for index in range(len(SCALES)) if (union >> index) & 1]


def _value_search(ftype: FieldType, cur: np.ndarray, mask: np.ndarray, value: int) -> tuple[np.ndarray, np.ndarray]:
    """``equal N``: every scale through which a candidate shows ``N`` stays in its mask.

    A pinned candidate keeps the scales of its mask that still show ``N``; an
    unpinned one takes every scale that shows it. A candidate with no scale
    left is dropped.
    """
    low, high = ftype.value_range()
    targets: dict[int, int] = {}  # stored value -> the mask of the scales that show it as N
    for index, candidate in enumerate(SCALES):
        stored = candidate.stored(value)
        if ftype.kind in candidate.kinds and stored is not None and low <= stored <= high:
            targets[stored] = targets.get(stored, 0) | 1 << index
    masks = np.zeros(len(cur), dtype=MASK_DTYPE)
    if not targets:
        return np.zeros(len(cur), dtype=bool), masks
    # Few positions hold any of the stored values: find them with one pass per
    # value, then tell which scales each matched only there.
    values = iter(targets)
    hit = cur == next(values)
    for stored in values:
        hit |= cur == stored
    where = np.flatnonzero(hit)
    found = cur[where]
    matched = np.zeros(len(where), dtype=MASK_DTYPE)
    for stored, bits in targets.items():
        matched[found == stored] |= MASK_DTYPE.type(bits)
    masks[where] = matched
    if not np.count_nonzero(mask):  # (UNPINNED is 0) nothing pinned yet: every hit is kept
        return hit, masks
    masks = np.where(mask != UNPINNED, masks & mask, masks)  # pinned ones keep only scales they had
    return masks != 0, masks


def list_candidates(engine: Engine, limit: int | None = None) -> list[Candidate]:
    """The candidates by address (then simplest type first), at most ``limit`` of them.

    Their values are gathered from each snapshot decoded as every type (:meth:`Engine.decoded`,
    a millisecond or two a snapshot), not decoded one by one: a listing of thousands of
    candidates over dozens of snapshots takes a fraction of a second, not a minute.
    """
    cands = engine.candidates
    found = [np.flatnonzero(alive) for alive in cands.alive]
    if limit is not None:
        found = [positions[:limit] for positions in found]
    positions = np.concatenate(found) if found else np.zeros(0, dtype=np.int64)
    kinds = np.concatenate([np.full(len(p), t, dtype=np.int64) for t, p in enumerate(found)]) if found else positions
    order = np.lexsort((kinds, positions))[:limit]
    positions, kinds = positions[order], kinds[order]
    if not len(positions):
        return []
    # What decode_all gives fits in int64, but for a u8 past 2**63 (Python ints, then).
    wide = any(value_dtype(engine.types[t]) == np.uint64 for t in np.unique(kinds).tolist())
    values = np.empty((len(positions), len(engine.snapshots)), dtype=object if wide else np.int64)
    present = [(t, kinds == t) for t in np.unique(kinds).tolist()]
    for index in range(len(engine.snapshots)):
        decoded = engine.decoded(index)
        for t, rows in present:
            values[rows, index] = decoded[t][positions[rows]]
    addresses = engine.layout.addresses(positions).tolist()
    out = []
    for row, position, t, address in zip(values.tolist(), positions.tolist(), kinds.tolist(), addresses):
        seen = tuple(row)
        changes = sum(a != b for a, b in pairwise(seen))
        mask = int(cands.scale[t][position])
        out.append(Candidate(int(address), engine.types[t].code, seen, scale_label(mask), changes, scale_labels(mask)))
    return out
