"""The NES's states (FCEUmm): how the core walks a state's chunks, which a state can send round in a loop.

An FCEUmm state is a 16-byte header (``FCS``, then the chunks' total size as
4 bytes, little-endian), then chunks, each a type byte, a 4-byte size and its
entries, each a 4-byte name, a 4-byte size and the bytes. The loader
(``FCEUSS_Load_Mem``) copies an entry whose name and size it knows into the
emulator, and skips any other entry, and any chunk of an unknown type, by
seeking past its size. The seek takes the size as a signed ``int``: a size of
2 GiB or more moves the stream back, so a size of ``-8`` returns to the
entry's own header and the loader reads it again forever (the raw core never
returns from loading it). :func:`fceumm_problem` walks the chunks as the loader
does and refuses a state whose chunks or entries do not fit where the core
writes them.

The values it copies need no check: the mappers reduce every bank number to
the ROM's banks as they map it (``setprg8`` and its kin mask with the ROM's
size), the PPU's addresses are masked to 14 bits where they are used, and the
sprite index is a byte over the 256-byte sprite memory (fuzzing every entry of
Hopper-Nes's states with extreme and random values killed no core).
"""

from __future__ import annotations

import struct

FCEUMM_MAGIC = b"FCS"
HEADER = 16
LOADED_CHUNKS = frozenset({1, 2, 3, 4, 5, 0x10})
"""The chunk types the loader reads entry by entry (CPU, CPU cycles, PPU, input, sound, the mapper's memory)."""


def fceumm_problem(state: bytes) -> str:
    """Why FCEUmm would loop forever loading ``state`` (``""`` when it would not)."""
    if not state.startswith(FCEUMM_MAGIC) or len(state) < HEADER:
        return ""  # the loader reads nothing from it
    (total,) = struct.unpack_from("<i", state, 4)
    at = HEADER
    while total > 0 and at + 5 <= len(state):  # as the loader: until the header's total is read, or the state ends
        kind = state[at]
        (size,) = struct.unpack_from("<I", state, at + 1)
        total -= size + 5
        at += 5
        end = at + size
        if end > len(state):
            return _unfit(f"a chunk of {size} bytes at offset {at - 5}")
        while kind in LOADED_CHUNKS and at < end:
            if at + 8 > end:
                return _unfit(f"an entry header cut by its chunk's end at offset {at}")
            (entry,) = struct.unpack_from("<I", state, at + 4)
            if at + 8 + entry > end:
                return _unfit(f"an entry of {entry} bytes at offset {at}, past its chunk's end")
            at += 8 + entry
        at = end
    return ""


def _unfit(what: str) -> str:
    return (
        f"its chunks do not fit where the core writes them ({what}), and the core's loader seeks by such a size, "
        "backwards for one of 2 GiB or more, so it reads the same bytes again forever"
    )
