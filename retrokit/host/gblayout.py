"""The Game Boy's states (gambatte): how the core walks a state's bytes, and the values it trusts from them.

gambatte's loader (``StateSaver::loadState``) reads the state through a
stream that has no end: every read takes bytes past the pointer, whatever the
buffer's size. A state is a version byte (0), a byte it skips, a 24-bit size
of a snapshot it skips, then entries, each a label ended by a NUL, a 24-bit
big-endian size and that many bytes. The label is copied into a buffer of 8
bytes up to its NUL, however far that is (the copy's limit is never counted):
a label of 8 characters or more writes past the buffer, into the heap. The
loader knows 113 labels in sorted order and stops only once it has met each
one in that order: an unknown label's entry is skipped by its size, and a
known one out of order is loaded without counting. So a state whose labels or
sizes are not as the core writes them makes it read past the state's end, into
whatever lies after it, until it happens on the labels it waits for or leaves
the process's memory (SIGSEGV). :func:`gambatte_entries` walks a state as the
loader does and refuses one whose walk leaves the state.

The values themselves are mostly made safe by the core as it loads them:
the PPU clamps its cycle count, pixel positions and window state and looks
its state machine's step up in a table that answers "none" for an unknown
one, the sound channels reduce their positions, and the cartridge reduces its
banks to those the cartridge has. One it takes as it is: the OAM DMA's last
update time (``lodmaup``), from which it counts the DMA's steps up to the CPU's
clock (``cc``); a time far from the clock leaves the core running billions of
steps (the raw core never returns). A core keeps it within a frame of the
clock, or "disabled" (``0xFFFFFFFF``).
"""

from __future__ import annotations

GAMBATTE_LABELS = tuple(
    b"a b bgatrb bgnatrb bgntw bgp bgtw c c1mastr c2mastr c3mastr c4mastr cc csprite d dmadst dmasrc dmgpal dut1ctr "
    b"dut1pos dut2ctr dut2pos e edM0tim endx env1ctr env1vol env2ctr env2vol env4ctr env4vol f h halt hdma hram ime l "
    b"lcdsirq ldivup len1ctr len1val len2ctr len2val len3ctr len3val len4ctr len4val lfsrctr lfsrreg lodmaup ltimaup "
    b"lwavrdt lyc m0lyc m0time minintt nm0irq nr10 nr13 nr14 nr23 nr24 nr33 nr34 nr44 nsprite objp odmapos oldwy pc "
    b"ppur0 ppur1 ppustat rambank rambmod rombank rtcbase rtcdh rtcdl rtch rtchalt rtclld rtcm rtcs serialt skip sp "
    b"spattr spbyte0 spbyte1 sposbuf spszbuf spucntr sram sramon swpcntr swpneg swpshdw tmatime unhaltt vcycles vram "
    b"wavectr wavepos waveram wavsmpl wemastr windraw winypos wram wscx xpos".split()
)
"""The labels gambatte's loader knows, in its (``strcmp``) order."""
MAX_LABEL = max(map(len, GAMBATTE_LABELS))
"""The most characters a label may have: the loader's buffer holds the longest label and its NUL."""


def gambatte_entries(state: bytes) -> dict[bytes, tuple[int, int]] | None:
    """Walk ``state`` as gambatte's loader does: each label it loads to where its value is (offset, size), the last
    load of each; ``None`` when the walk would leave the state or overflow the label buffer (``{}`` when the core
    loads nothing)."""
    if len(state) < 5 or state[0] != 0:
        return {}  # the loader gives up at once
    at = 5 + int.from_bytes(state[2:5], "big")
    done = 0
    entries: dict[bytes, tuple[int, int]] = {}
    while done < len(GAMBATTE_LABELS):
        end = state.find(b"\0", at, at + MAX_LABEL + 1)
        if end < 0 or end + 4 > len(state):
            return None  # a longer label overruns the loader's buffer (its getline never counts)
        label = state[at:end]
        size = int.from_bytes(state[end + 1 : end + 4], "big")
        at = end + 4
        if label == GAMBATTE_LABELS[done]:
            done += 1
        elif label not in GAMBATTE_LABELS[done + 1 :]:
            at += size
            continue  # skipped, unknown here
        if at + size > len(state):
            return None
        entries[label] = (at, size)
        at += size
    return entries


def _value(state: bytes, where: tuple[int, int]) -> int:
    """A scalar as the loader reads it: the last (up to) 4 bytes of its entry, big-endian."""
    at, size = where
    return int.from_bytes(state[at + max(size - 4, 0) : at + size], "big")


DISABLED = 0xFFFFFFFF
"""The time gambatte gives an event that is not pending."""
FRAME_CYCLES = 2 * 70224
"""CPU cycles of one frame at double speed: the furthest a pending event is from the CPU's cycle counter."""
GAMBATTE_TIMES = {
    b"lodmaup": "the OAM DMA's last update, from which the core counts the DMA's steps to run",
}
"""The event times the core counts from the CPU's cycle counter (``cc``), and what it does with them."""


def gambatte_problem(state: bytes) -> str:
    """Why gambatte would read or index outside its memory, or never return, with ``state`` (``""`` when it would
    not)."""
    entries = gambatte_entries(state)
    if entries is None:
        return (
            "its entries do not parse as the core writes them (a label unended or a size off), so the core's loader "
            "writes past its label buffer or reads on past the state's end, into memory it does not own"
        )
    if b"cc" not in entries:
        return ""
    now = _value(state, entries[b"cc"]) & 0x7FFFFFFF  # as the loader keeps it
    for label, why in GAMBATTE_TIMES.items():
        if label not in entries or (time := _value(state, entries[label])) == DISABLED:
            continue
        away = (time - now + 2**31) % 2**32 - 2**31
        if abs(away) > FRAME_CYCLES:
            return (
                f"its {label.decode()} ({why}) is {away:+} cycles from its CPU's clock, where a core keeps it within "
                f"a frame ({FRAME_CYCLES}), so the core runs that count and never returns"
            )
    return ""
