"""The RAM a search looks at: the mapped regions of a console, as console-order bytes.

A :class:`RamLayout` lays the writable regions of an emulator's
:class:`~retrokit.host.memory.AddressSpace` end to end, so a snapshot is one
flat ``uint8`` array. Each region's bytes are put back in console order (the
Genesis core keeps its RAM as byte-swapped words: console address ``a`` is at
offset ``(a & 0xFFFF) ^ 1``), so a multi-byte value reads in the order the
console's CPU reads it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from retrokit.errors import InvalidArgumentError
from retrokit.host.memory import AddressSpace


@dataclass(frozen=True)
class RamLayout:
    """Where each RAM region sits in a flat snapshot.

    Attributes:
        regions: ``(console start address, length)`` of each region, in snapshot order.
    """

    regions: tuple[tuple[int, int], ...]

    @classmethod
    def of(cls, space: AddressSpace) -> RamLayout:
        """The layout of an address space's regions."""
        return cls(tuple((r.start, r.length) for r in space.regions))

    @property
    def size(self) -> int:
        """The bytes in a snapshot."""
        return sum(length for _, length in self.regions)

    @property
    def digits(self) -> int:
        """Hex digits an address is written with (4 at least, as game files do)."""
        return max(4, *(len(f"{start + length - 1:X}") for start, length in self.regions))

    def format(self, address: int) -> str:
        """Write an address as a game.yaml does, e.g. ``0xFF002B``."""
        return f"0x{address:0{self.digits}X}"

    def describe(self) -> str:
        """The regions' address ranges, e.g. ``0xFF0000-0xFFFFFF``."""
        return ", ".join(f"{self.format(s)}-{self.format(s + n - 1)}" for s, n in self.regions) or "none"

    def starts(self) -> np.ndarray:
        """The snapshot position of each region's first byte."""
        return np.cumsum([0] + [length for _, length in self.regions])[:-1]

    def addresses(self, positions: np.ndarray) -> np.ndarray:
        """The console addresses of snapshot positions."""
        positions = np.asarray(positions, dtype=np.int64)
        starts = self.starts()
        region = np.searchsorted(starts, positions, side="right") - 1
        bases = np.array([s for s, _ in self.regions], dtype=np.int64)
        return bases[region] + positions - starts[region]

    def position(self, address: int, width: int = 1) -> int:
        """The snapshot position of a console address.

        Raises:
            InvalidArgumentError: The ``width`` bytes at ``address`` are not all in one RAM region.
        """
        offset = 0
        for start, length in self.regions:
            if start <= address and address + width <= start + length:
                return offset + address - start
            offset += length
        raise InvalidArgumentError(
            f"Expected an address in RAM ({self.describe()}), got {self.format(address) if address >= 0 else address}"
            + (f" with {width} bytes" if width > 1 else "")
            + ". Give a console address inside a RAM region, as `retrokit ramsearch show` prints them."
        )

    def valid(self, width: int) -> np.ndarray:
        """Which positions start ``width`` bytes that lie inside one region."""
        mask = np.zeros(self.size, dtype=bool)
        for begin, (_, length) in zip(self.starts(), self.regions):
            mask[begin : begin + max(0, length - width + 1)] = True
        return mask

    def read(self, space: AddressSpace) -> np.ndarray:
        """Copy the RAM into a new snapshot of console-order bytes.

        Raises:
            InvalidArgumentError: The address space's regions differ from this layout.
        """
        if RamLayout.of(space) != self:
            raise InvalidArgumentError(
                f"Expected RAM regions {self.describe()}, found {RamLayout.of(space).describe()}."
            )
        parts = [
            _console_order(region.buffer, region.length, [region.offset(region.start + k) for k in range(region.swap)])
            for region in space.regions
        ]
        return np.concatenate(parts) if len(parts) != 1 else parts[0]


def _console_order(buffer: memoryview, length: int, pattern: Sequence[int]) -> np.ndarray:
    """Bytes of a region in console order; ``pattern`` is the buffer offset of each byte of the first word."""
    raw = np.frombuffer(buffer, dtype=np.uint8)[:length]
    swap = len(pattern)
    if list(pattern) == list(range(swap)):
        return raw.copy()
    if length % swap:
        raise InvalidArgumentError(
            f"Expected a region length that is a multiple of its {swap}-byte words, got {length}."
        )
    return raw.reshape(-1, swap)[:, list(pattern)].ravel()
