"""The search engine: candidates over snapshots, narrowed by filters, with undo and redo.

A candidate is a type and a snapshot position (the value of that type that
starts there), with the scale a value search matched it with
(:mod:`retrokit.ramsearch.scales`). Candidates are kept as one boolean array
per type over every position, so a filter is a few numpy comparisons over the
type's decoded values (:mod:`retrokit.ramsearch.types`); once few candidates
are left, only their positions are compared.

The filters themselves are described in :mod:`retrokit.ramsearch.filters`;
the candidate set in :mod:`retrokit.ramsearch.candidates`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from retrokit.errors import InvalidArgumentError, RamSearchError
from retrokit.host.typecodes import FieldType
from retrokit.ramsearch.candidates import Candidates, Packed
from retrokit.ramsearch.filters import CHANGES, COMPARISONS, Filter, check_filter
from retrokit.ramsearch.ram import RamLayout
from retrokit.ramsearch.scales import SCALES, UNPINNED
from retrokit.ramsearch.types import decode_all

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
        value_search = spec.than is None and spec.op == "equal"
        if value_search:  # it pins scales: on a copy
            scales = self.candidates.scale[t] = scales.copy()
        if left * _SPARSE < len(alive):  # few left: compare only their positions
            positions = np.flatnonzero(alive)

            def pick(a: np.ndarray) -> np.ndarray:
                return a[positions]

            scale = scales[positions]
            kept = alive.copy()
            kept[positions] = self._compare(t, spec, pick(self.decoded(-1)[t]), scale, pick)
            self.candidates.alive[t] = kept
            if value_search:
                scales[positions] = scale
        else:
            self.candidates.alive[t] = alive & self._compare(t, spec, self.decoded(-1)[t], scales, lambda a: a)

    def _compare(self, t: int, spec: Filter, cur: np.ndarray, scale: np.ndarray, pick) -> np.ndarray:
        ftype = self.types[t]
        if spec.than is None and spec.op == "equal":
            return _value_search(ftype, cur, scale, spec.value)
        if spec.than == "changes":
            return COMPARISONS[spec.op](pick(self._counts[t]), spec.value)
        scaled = bool((scale > 0).any())  # else every value is shown as stored: compare the compact arrays
        shown, ok = _shown(cur, scale) if scaled else (cur, None)
        if spec.than is None:
            ref, ref_ok = spec.value, None
        elif isinstance(spec.than, int):  # another address: its stored value in the newest snapshot
            try:
                position = self.layout.position(spec.than, ftype.width)
            except InvalidArgumentError:
                return np.zeros(len(cur), dtype=bool)
            ref, ref_ok = self.decoded(-1)[t][position], None
        else:
            ref = pick(self.decoded(0 if spec.than == "first" else -2)[t])
            ref, ref_ok = _shown(ref, scale) if scaled else (ref, None)
        if spec.op == "changed-by":
            result = _changed_by(shown, ref, spec.value)
        else:
            result = COMPARISONS[CHANGES.get(spec.op, spec.op)](shown, ref)
        for defined in (ok, ref_ok):
            if defined is not None:
                result &= defined
        return result

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


def _shown(stored: np.ndarray, scale: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The shown values of candidates (as int64), and where they are defined (exact division)."""
    shown, ok = stored.astype(np.int64), np.ones(len(stored), dtype=bool)
    for index in np.unique(scale[scale > 0]):
        where = scale == index
        shown[where], ok[where] = SCALES[index].shown(stored[where])
    return shown, ok


def _value_search(ftype: FieldType, cur: np.ndarray, scale: np.ndarray, value: int) -> np.ndarray:
    """``equal N``: pinned candidates by their scale; the others by the first scale that matches, which pins it."""
    pinned = scale != UNPINNED
    any_pinned = bool(pinned.any())
    if any_pinned:
        shown, ok = _shown(cur, np.where(pinned, scale, 0).astype(np.int8))
        keep = pinned & ok & (shown == value)
    else:
        keep = np.zeros(len(cur), dtype=bool)
    low, high = ftype.value_range()
    targets = []  # (scale index, stored value), first preferred
    for index, candidate in enumerate(SCALES):
        stored = candidate.stored(value)
        if ftype.kind not in candidate.kinds or stored is None or not low <= stored <= high:
            continue
        if all(stored != s for _, s in targets):
            targets.append((index, stored))
    if not targets:
        return keep
    # Few positions hold any of the stored values: find them with one pass per
    # value, then tell which scale each matched only there.
    hit = cur == targets[0][1]
    for _, stored in targets[1:]:
        hit |= cur == stored
    if any_pinned:
        hit &= ~pinned
    where = np.flatnonzero(hit)
    found = cur[where]
    chosen = np.empty(len(where), dtype=np.int8)
    for index, stored in reversed(targets):
        chosen[found == stored] = index
    scale[where] = chosen
    keep[where] = True
    return keep
