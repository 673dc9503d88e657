"""Scaled matches: how a value the screen shows may be stored in RAM.

Gym Retro's value search also finds a value stored divided by a power of 10
or of 16 (a score shown as 1230 kept as 123), doubled or quadrupled, or off
by one (3 lives shown, 2 stored). A :class:`Scale` says how the shown value
follows from the stored one: ``shown = stored * mult / div + bias``, the
division exact. retrokit adds the stored-multiplied cases the other way round
(3 shown, ``0x30`` stored is ``/16``), for integers shifted by a nibble: a
shift by a whole byte, or a BCD digit, is already another type read at a
nearby address.

A candidate keeps every scale that is still consistent with the value searches
so far, as a bit mask over :data:`SCALES` (bit ``i`` for ``SCALES[i]``): at
``equal 1`` a stored 2 is both "shown + 1" and "shown x 2", and only the next
value search tells them apart. :data:`UNPINNED` (no bit) is a candidate no
value search has matched yet, read as the value itself.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from retrokit.host.typecodes import BCD, LOW_BCD, SIGNED, UNSIGNED


@dataclass(frozen=True)
class Scale:
    """One way a shown value is stored.

    Attributes:
        label: How the shown value follows from the stored one, e.g. ``"x10"``
            (shown = stored * 10), ``"/16"``, ``"+1"``; ``""`` for the value itself.
        mult: Multiplies the stored value.
        div: Divides it (exactly).
        bias: Is added last.
        kinds: The type kinds it applies to.
    """

    label: str
    mult: int = 1
    div: int = 1
    bias: int = 0
    kinds: tuple[int, ...] = (UNSIGNED, SIGNED, BCD, LOW_BCD)

    def stored(self, shown: int) -> int | None:
        """The stored value that shows as ``shown``, or ``None`` if none does."""
        numerator = (shown - self.bias) * self.div
        if numerator % self.mult:
            return None
        return numerator // self.mult

    def shown(self, stored: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The shown values of stored ones, and where the division is exact."""
        product = stored.astype(np.int64) * self.mult
        return product // self.div + self.bias, product % self.div == 0


IDENTITY = Scale("")

#: Every scale, in the order a value search prefers them when several match.
SCALES: tuple[Scale, ...] = (
    IDENTITY,
    Scale("+1", bias=1),
    Scale("-1", bias=-1),
    *(Scale(f"x{10**k}", mult=10**k) for k in range(1, 10)),
    *(Scale(f"x{16**k}", mult=16**k) for k in range(1, 8)),
    Scale("/2", div=2),
    Scale("/4", div=4),
    Scale("/16", div=16, kinds=(UNSIGNED, SIGNED)),
)

UNPINNED = 0  # a candidate no value search has matched yet (no scale bit): read as the value itself
MASK_DTYPE = np.dtype(np.uint32)  # one bit per scale
ALL_SCALES = (1 << len(SCALES)) - 1
_LABELS_SHOWN = 3


def bits(mask: int) -> list[int]:
    """The scale indices whose bit is set in ``mask``, in :data:`SCALES` order."""
    return [index for index in range(len(SCALES)) if mask >> index & 1]


@functools.lru_cache(maxsize=1024)
def scale_labels(mask: int) -> tuple[str, ...]:
    """The labels of the scales in ``mask`` (``""`` for the value itself); none when unpinned."""
    return tuple(SCALES[index].label for index in bits(mask))


@functools.lru_cache(maxsize=1024)
def scale_label(mask: int) -> str:
    """How ``show`` writes a candidate's scales: ``""`` for the value itself (or unpinned), else e.g. ``"-1,/2"``."""
    labels = [label or "=" for label in scale_labels(mask)]
    if labels in ([], ["="]):
        return ""
    more = len(labels) - _LABELS_SHOWN
    return ",".join(labels[:_LABELS_SHOWN]) + (f",+{more} more" if more > 0 else "")
