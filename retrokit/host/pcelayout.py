"""The PC Engine's states (mednafen_pce_fast): the values the core trusts from a state, and their legal ranges.

The core's state is mednafen's format: a 32-byte header (``MDFNSVST``), then
sections, each a 32-byte name and a 4-byte size, holding variables, each a
1-byte name length, the name, a 4-byte size and the bytes. Loading walks the
sections the core asks for in order, each found as the first of its name, and
copies in every variable of that section whose name and size it knows (a later
copy of a variable overwrites an earlier one); nothing it copies is checked.
A variable that runs past its section trips the core's ``assert`` (compiled
out of the wheel's build, which then loses its place in the stream).

What the core does with some of those values:

- the VCE's dot clock (``vce.dot_clock``, which the core itself only sets to
  0, 1 or 2) indexes ``defined_width[3]``: the frame's width is read from past
  the table, so the core draws lines of a garbage width into a buffer sized for
  512 pixels (a SIGSEGV, a heap corruption) or hands the host a frame of
  terabytes;
- the CPU's ``timestamp`` and its next events (``timer_next_timestamp``,
  ``previous_next_user_event``) are cycle counts within the frame (the core
  rebases them to 0 at the end of every frame, so a state holds values near
  0); the sound buffer holds 50 ms of cycles from 0, and the PSG writes its
  samples at the timestamp's position, so a timestamp or an event billions of
  cycles away writes past the buffer;
- the PSG's channel selector (``select``) indexes its 6 channels (a game can
  write 0 to 7), and each channel's ``waveform_index`` indexes its 32-byte
  waveform, which a game's write to the waveform port then stores into
  (the core keeps it ``& 0x1F``);
- the Street Fighter II mapper's latch (``HuCSF2Latch``) picks a 512 KiB bank
  of the ROM past its first (the core writes ``A & 3``).

The PSG's volumes, waveform samples and counters are reduced by the core
itself after a load, and every VRAM address is checked against the VRAM's
size where it is used, so they need no check here. Nor do the CPU's memory
map registers (``MPR``): each is a byte, and the tables it indexes (the banks'
memory and read and write handlers) have 256 entries, every one of them set.
A map that is legal byte by byte can still send the emulated program astray
(the fuzz found two that kill the raw core, with SIGBUS, after a few hundred
frames): code run from the wrong bank writes what it likes to the hardware,
as a ROM could, and the core trusts some of those writes (a PSG channel
selector of 6 or 7 indexes past its 6 channels). That depends on no host
memory layout, so the crash comes at the same frame in every process, and the
probe, which plays the state in a child first, refuses it.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

MEDNAFEN_MAGIC = (b"MDFNSVST", b"MEDNAFENSVESTATE")
"""What a mednafen state's 32-byte header begins with (the core loads nothing else)."""
HEADER = 32
SECTION_NAME = 32
FRAME_CYCLES = 455 * 263
"""CPU cycles of one frame (263 lines of 455): the furthest a timestamp or an event is from the frame's start."""


@dataclass(frozen=True)
class Rule:
    """A variable the core trusts, and the values it may hold.

    Attributes:
        section: The section's name (``b"CPU"``).
        name: The variable's name.
        fmt: Its struct format (little-endian), which fixes its size.
        low: The smallest legal value.
        high: The largest legal value.
        why: What the core does with it, for the error.
    """

    section: bytes
    name: bytes
    fmt: str
    low: int
    high: int
    why: str


_TIMES = "a cycle count within the frame, which places writes into the 50 ms sound buffer"
PCE_RULES = (
    Rule(b"VCE", b"dot clock", "<B", 0, 2, "it indexes the table of the frame's 3 widths"),
    Rule(b"CPU", b"timestamp", "<i", 0, FRAME_CYCLES, _TIMES),
    Rule(b"CPU", b"timer_next_timestamp", "<i", -FRAME_CYCLES, FRAME_CYCLES, _TIMES),
    Rule(b"CPU", b"previous_next_user_event", "<i", -FRAME_CYCLES, FRAME_CYCLES, _TIMES),
    Rule(b"PSG", b"select", "<B", 0, 7, "it indexes the PSG's channels"),
    Rule(b"HuC", b"HuCSF2Latch", "<B", 0, 3, "it picks one of the Street Fighter II mapper's 4 ROM banks"),
    *(
        Rule(f"SCH{ch}".encode(), b"waveform_index", "<B", 0, 31, "it indexes the channel's 32-sample waveform")
        for ch in range(6)
    ),
)


def mednafen_sections(state: bytes) -> dict[bytes, list[tuple[bytes, int, int]]] | None:
    """The sections the core would find in ``state``: each name (its first occurrence) to its variables, each
    ``(name, offset, size)``; ``None`` when a section or variable runs past its bounds (which no core writes)."""
    sections: dict[bytes, list[tuple[bytes, int, int]]] = {}
    at = HEADER
    while at < len(state):
        if at + SECTION_NAME + 4 > len(state):
            return None
        name = state[at : at + SECTION_NAME].split(b"\0", 1)[0]
        (size,) = struct.unpack_from("<I", state, at + SECTION_NAME)
        at += SECTION_NAME + 4
        end = at + size
        if end > len(state):
            return None
        variables = []
        while at < end:
            length = state[at]
            if at + 1 + length + 4 > end:
                return None
            variable = state[at + 1 : at + 1 + length]
            (vsize,) = struct.unpack_from("<I", state, at + 1 + length)
            at += 1 + length + 4
            if at + vsize > end:
                return None
            variables.append((variable, at, vsize))
            at += vsize
        sections.setdefault(name, variables)
    return sections


def pce_problem(state: bytes) -> str:
    """Why mednafen_pce_fast would index outside its memory with ``state`` (``""`` when it would not)."""
    if not state.startswith(MEDNAFEN_MAGIC):
        return ""  # the core loads nothing from it
    sections = mednafen_sections(state)
    if sections is None:
        return (
            "its sections or variables run past their stated sizes (the core writes them exactly), which leaves the "
            "core reading the rest of the state from the wrong place"
        )
    for rule in PCE_RULES:
        size = struct.calcsize(rule.fmt)
        for name, at, vsize in sections.get(rule.section, ()):
            if name != rule.name or vsize != size:
                continue  # the core skips a variable of another size
            (value,) = struct.unpack_from(rule.fmt, state, at)
            if not rule.low <= value <= rule.high:
                return (
                    f"its {rule.section.decode()} {rule.name.decode()} is {value}, outside {rule.low} to {rule.high} "
                    f"({rule.why}), so the core reaches memory it does not own"
                )
    return ""
