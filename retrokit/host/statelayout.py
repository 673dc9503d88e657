"""What a core would do with a state's bytes that no probe can see: pointers built from them, unchecked.

Genesis Plus GX restores the cartridge's memory map from a state (its
``md_cart_context_load``): for each of the 68000's 64 banks of 64 KiB the
state holds one byte, ``0xFF`` for the battery RAM, else the bank of the ROM
area to map there, and the core sets the bank's pointer to
``cart.rom + (byte << 16)``. Its ROM area holds ``MAXROMSIZE`` (10 MiB, 160
banks), and the core does not check the byte: a state whose byte is 0xA0 to
0xFE maps a bank up to 6 MiB past the end of that array. Reading the bank
then reads whatever this process happens to have there: nothing (SIGSEGV), or
another library's memory. Whether anything is mapped there depends on the
process's memory layout, so a probe in a child may pass such a state while the
same state kills the user's process (a corrupt state of the fuzz of issue 24
did this about one run in two, at its third load, in ``system_reset``).

The Z80's window into the 68000's space is the same: its base address
(``zbank``) is restored from the state as 4 bytes, and the core indexes its
256-entry table of handlers with ``(zbank | offset) >> 16``, so a base above
24 bits (the core itself only ever writes ``& 0xFF8000``) calls a function
pointer read from past the table.

The VDP's FIFO is the same again: its write index (``fifo_idx``, 4 bytes) is
restored from the state, and the next write to the VDP's data port stores at
``fifo[fifo_idx]`` in a 4-entry array (the core itself keeps the index
``& 3``): 0x40000000 is a SIGSEGV at the game's next VDP write.

So such a state is refused by reading those bytes, before any probe: the
verdict does not depend on luck. No state a core writes has such a byte (the
core maps banks only inside its ROM area): the 928 Genesis states that
stable-retro ships all pass.

In Master System and Game Gear mode the same core's states need a check of
their own. Their cartridge mapper registers are safe: the core reduces each
bank byte modulo the cartridge's page count when it rebuilds the map
(``mapper_16k_w`` and its siblings), and maps nothing when no ROM is enabled.
But the sound section holds the YM2413 (FM) chip's whole C struct, copied in
as raw bytes, and the chip's update, which runs every frame whether a game
uses FM or not, reads ``sin_tab[slot->wavetable + ...]``: the 18 operators'
``wavetable`` fields are unchecked 32-bit table offsets, which the core
itself only ever sets to 0 or ``SIN_LEN`` (1024). A state with any other value
reads past the table: 0x40000000 kills the process with SIGSEGV
(tests/test_hostile_states.py), smaller ones read whatever lies there.

Stella (stable-retro's 3.9 build) restores a bank-switched cartridge's banks
from a state as 16-bit numbers (``CartridgeF8::load`` and its kin) and maps
the bank at ``myImage + (bank << 12)`` (1 KiB slices for E0, 2 KiB for E7)
without checking the number against the ROM's banks. The cartridge's part of a
state begins with its class name (a 4-byte length, then the name), which the
core checks before reading on; so every place the name occurs is checked, and a
name planted earlier in the state cannot hide the one the core reads (but the
copy of the name in the state's header, which the core only compares).

The PC Engine, Game Boy, NES and SNES cores have checks of their own, one
module each beside this one, for their formats differ: mednafen's named
sections (timestamps, the dot clock, indexes), gambatte's labelled entries
read by a loader that has no end, FCEUmm's chunks whose sizes it seeks by as
signed numbers, and snes9x's blocks of timings, clocks and sound-chip
positions. :data:`_CHECKS` is the one table every state load goes through.
"""

from __future__ import annotations

import struct
from collections.abc import Callable

from retrokit.host.gblayout import gambatte_problem
from retrokit.host.neslayout import fceumm_problem
from retrokit.host.pcelayout import pce_problem
from retrokit.host.sneslayout import snes9x_problem

GENESIS_STATE_SIZE = 1036288
"""Bytes of a Genesis Plus GX 1.7.5 state (its ``STATE_SIZE``, 0xFD000)."""
GENESIS_SIGNATURE = b"GENPLUS-GX 1.7.5"
"""The 16 bytes every Genesis Plus GX 1.7.5 state begins with."""
GENESIS_BANK_MAP = 144613
"""Where a Mega Drive state's 64 bank bytes begin: after the work RAM, Z80 RAM, I/O, VDP, sound, 68000 and Z80
contexts, whose sizes are fixed for a Mega Drive cartridge (the bytes of a plain ROM's state there read 0, 1, ..., 63)."""
GENESIS_Z80_BANK = 16 + 0x10000 + 0x2000 + 1
"""Where a Mega Drive state's Z80 bank address (4 bytes, little-endian) is: after the signature, the 68000's
work RAM, the Z80's RAM and the Z80's bus state."""
GENESIS_Z80_BANK_BITS = 0xFF8000
"""The bits a Z80 bank address may have: 9 bits of bank, in the 68000's 24-bit space."""
GENESIS_FIFO_INDEX = 16 + 0x10000 + 0x2000 + 1 + 4 + 0x10 + 0x400 + 0x10000 + 0x80 + 0x80 + 0x20 + 12
"""Where a Mega Drive state's VDP FIFO write index (4 bytes, little-endian, 0 to 3) is: after the Z80's bank address,
the I/O registers, and the VDP's sprite table, VRAM, CRAM, VSRAM, registers and its first 12 bytes of state."""
GENESIS_FIFO_SIZE = 4
GENESIS_BANKS = 0x40
GENESIS_ROM_BANKS = 10485760 >> 16
"""Banks of 64 KiB in the core's ROM area (``MAXROMSIZE``, 10 MiB): a bank byte must be below this, or 0xFF."""
_SRAM = 0xFF


STELLA_BANKS: dict[bytes, tuple[int, ...]] = {
    b"CartridgeF8": (2,), b"CartridgeF8SC": (2,), b"CartridgeF6": (4,), b"CartridgeF6SC": (4,),
    b"CartridgeF4": (8,), b"CartridgeF4SC": (8,), b"CartridgeFA": (3,), b"CartridgeUA": (2,),
    b"CartridgeEF": (16,), b"CartridgeF0": (16,), b"CartridgeE0": (8, 8, 8, 8), b"CartridgeE7": (8, 8, 4),
}
"""Stella's bank-switched cartridge classes whose state holds bank numbers it uses unchecked: for each 16-bit
number that follows the class name, the banks (slices, RAM pages) of that kind the cartridge has."""


MS_YM2413 = 16 + 0x2000 + 0x10 + 66886
"""Where a Master System / Game Gear state's YM2413 struct begins: after the signature, the 8 KiB work RAM, the
16 I/O registers and the VDP's context (sprite table, VRAM, CRAM, VSRAM, registers and its 38 bytes of state)."""
YM2413_CHANNELS = 9
YM2413_CHANNEL_SIZE = 184
"""Bytes of one channel (two operators of 84 bytes and its own 16) in the x86-64 build of the struct."""
YM2413_SLOT_SIZE = 84
YM2413_WAVETABLE = 80
"""Where an operator's ``wavetable`` (4 bytes, little-endian) is within it."""
YM2413_WAVETABLES = (0, 1024)
"""The offsets into ``sin_tab`` the core writes: the full sine, or the half-rectified one ``SIN_LEN`` entries on."""


def _genesis_problem(state: bytes) -> str:
    (z80_bank,) = struct.unpack_from("<I", state, GENESIS_Z80_BANK)
    if z80_bank & ~GENESIS_Z80_BANK_BITS:
        return (
            f"its Z80 bank address is {z80_bank:#x}, outside the 68000's 24-bit space (a core writes only "
            f"addresses within {GENESIS_Z80_BANK_BITS:#x}), which reads memory the core does not own"
        )
    (fifo_index,) = struct.unpack_from("<I", state, GENESIS_FIFO_INDEX)
    if fifo_index >= GENESIS_FIFO_SIZE:
        return (
            f"its VDP FIFO write index is {fifo_index:#x}, past the FIFO's {GENESIS_FIFO_SIZE} entries (a core keeps "
            "it below 4), so the next VDP write stores into memory the core does not own"
        )
    banks = state[GENESIS_BANK_MAP : GENESIS_BANK_MAP + GENESIS_BANKS]
    wild = [(i, b) for i, b in enumerate(banks) if GENESIS_ROM_BANKS <= b < _SRAM]
    if not wild:
        return ""
    bank, value = wild[0]
    return (
        f"its cartridge memory map points {len(wild)} of the 68000's {GENESIS_BANKS} banks outside the core's ROM "
        f"area (bank {bank:#04x} at ROM bank {value:#04x}; the area holds {GENESIS_ROM_BANKS:#04x}), which reads "
        "memory the core does not own"
    )


def _master_system_problem(state: bytes) -> str:
    wild = []
    for channel in range(YM2413_CHANNELS):
        for slot in range(2):
            at = MS_YM2413 + channel * YM2413_CHANNEL_SIZE + slot * YM2413_SLOT_SIZE + YM2413_WAVETABLE
            (offset,) = struct.unpack_from("<I", state, at)
            if offset not in YM2413_WAVETABLES:
                wild.append((channel, slot, offset))
    if not wild:
        return ""
    channel, slot, offset = wild[0]
    return (
        f"its YM2413 sound chip indexes its sine table with {len(wild)} wild offset(s) (channel {channel} operator "
        f"{slot + 1} at {offset:#x}; a core writes only {' or '.join(map(str, YM2413_WAVETABLES))}), which reads "
        "memory the core does not own"
    )


def _stella_problem(state: bytes) -> str:
    """The stella check: every bank number after a bank-switched cartridge's class name is one of its banks."""
    # A state begins with two strings: the format's header, then the cartridge's class name, which the core only
    # compares; the name's copy that holds the banks comes after the console's chips.
    header = 4 + struct.unpack_from("<I", state)[0] if len(state) >= 4 else 0
    for name, limits in STELLA_BANKS.items():
        marker = struct.pack("<I", len(name)) + name
        at = state.find(marker)
        while at >= 0:
            start = at + len(marker)
            if at != header and start + 2 * len(limits) <= len(state):  # a shorter state fails the load before any bank is mapped
                numbers = struct.unpack_from(f"<{len(limits)}H", state, start)
                for number, banks in zip(numbers, limits, strict=True):
                    if number >= banks:
                        return (
                            f"its {name.decode()} cartridge is in bank {number}, of the {banks} it has there, "
                            "which maps memory the core does not own"
                        )
            at = state.find(marker, at + 1)
    return ""


def cartridge_class(state: bytes) -> str:
    """The cartridge class a stella state names after its header (``"CartridgeF8SC"``); ``""`` for any other state."""
    names = []
    at = 0
    for _ in range(2):  # the format's header, then the cartridge's class name: two length-prefixed strings
        if at + 4 > len(state):
            return ""
        length = struct.unpack_from("<I", state, at)[0]
        if length > 64 or at + 4 + length > len(state):
            return ""
        names.append(state[at + 4 : at + 4 + length])
        at += 4 + length
    name = names[1]
    return name.decode("ascii") if name.startswith(b"Cartridge") and name.isascii() else ""


def _genesis_plus_gx(check: Callable[[bytes], str]) -> Callable[[bytes], str]:
    """``check``, on a state in Genesis Plus GX 1.7.5's format only (the same size and signature in every mode; the
    system, from the ROM's extension, decides how the core reads the rest)."""

    def checked(state: bytes) -> str:
        if len(state) != GENESIS_STATE_SIZE or not state.startswith(GENESIS_SIGNATURE):
            return ""
        return check(state)

    return checked


_CHECKS: dict[str, Callable[[bytes], str]] = {
    "Genesis": _genesis_plus_gx(_genesis_problem),
    "Sms": _genesis_plus_gx(_master_system_problem),
    "GameGear": _genesis_plus_gx(_master_system_problem),
    "Atari2600": _stella_problem,
    "PCEngine": pce_problem,
    "GameBoy": gambatte_problem,
    "GbColor": gambatte_problem,
    "Nes": fceumm_problem,
    "Snes": snes9x_problem,
}
"""The systems whose states are checked, by their core's layout."""


def state_layout_problem(system: str, state: bytes) -> str:
    """Why the core would build a pointer outside its own memory from ``state`` (``""`` when it would not).

    Only what is known of a core's layout is checked: a Genesis, Master
    System or Game Gear state in Genesis Plus GX 1.7.5's format, an Atari 2600
    state in stella's, a PC Engine state in mednafen's
    (:mod:`retrokit.host.pcelayout`), a Game Boy or Game Boy Color state in
    gambatte's (:mod:`retrokit.host.gblayout`), an NES state in FCEUmm's
    (:mod:`retrokit.host.neslayout`), a SNES state in snes9x's
    (:mod:`retrokit.host.sneslayout`). Anything else is left to the probe, as
    is what no layout shows: a state whose values are each legal but send the
    emulated program astray (a PC Engine state whose memory map puts the
    stack in ROM) crashes, if it does, at the same frame in any process.

    Args:
        system: The system's name (``"Genesis"``).
        state: The serialized state.
    """
    check = _CHECKS.get(system)
    return check(state) if check else ""
