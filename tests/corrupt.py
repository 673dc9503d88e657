"""Corrupt Genesis states for tests: a real state's header, then random bytes.

A random body nearly always holds bytes the core turns into wild pointers (its
memory map, its Z80 bank address, its VDP FIFO index), which :mod:`retrokit.host.statelayout`
refuses before any probe. With ``keep_pointers`` those bytes are the real
state's, so only the probe can tell whether the core survives the rest.
"""

from __future__ import annotations

import random

from retrokit.host.statelayout import GENESIS_BANK_MAP, GENESIS_BANKS, GENESIS_FIFO_INDEX, GENESIS_Z80_BANK

HEADER = 16  # "GENPLUS-GX 1.7.5": the core's signature, checked by the core on load
POINTERS = (
    slice(GENESIS_BANK_MAP, GENESIS_BANK_MAP + GENESIS_BANKS),
    slice(GENESIS_Z80_BANK, GENESIS_Z80_BANK + 4),
    slice(GENESIS_FIFO_INDEX, GENESIS_FIFO_INDEX + 4),
)


def random_body(good: bytes, rng: random.Random, *, keep_pointers: bool) -> bytes:
    """``good``'s header and a random body from ``rng`` (with ``good``'s pointer bytes, with ``keep_pointers``)."""
    state = bytearray(good[:HEADER] + rng.randbytes(len(good) - HEADER))
    if keep_pointers:
        for where in POINTERS:
            state[where] = good[where]
    return bytes(state)
