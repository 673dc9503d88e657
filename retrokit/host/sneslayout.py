"""The SNES's states (snes9x): the timings, counters and sound-chip indexes the core takes from a state as they are.

A snes9x state is a header (``#!s9xsnp:0009`` and a newline), then blocks,
each a 3-letter name, ``:``, its length (6 decimal digits, or ``-`` and 4
bytes), ``:`` and its bytes. The core reads each block it expects into a
buffer of the block's size (zero-filled past what the state holds) and copies
the fields in, big-endian. It checks none of these against what it itself
would write:

- the line and frame timings (``TIM``): a line of ``H_Max`` cycles and a
  frame of ``V_Max`` lines, and where in the line each event falls; the core
  sets them from constants (1364 cycles, or 1360 on the short line; 262 or
  312 lines, one more in an interlaced field; events inside the line; the
  DMA's and the interrupts' delays of a few dozen cycles). A line of no cycles,
  an event outside it, or a delay of billions of cycles, and the frame never
  ends (the raw core never returns);
- the CPU's clock (``CPU``): its cycle count, the next event's cycle and which
  event it is (one of 6), its line (``V_Counter``) and the fast ROM's access
  time (6 or 8 cycles). An unknown event is never handled, so the line never
  ends; a cycle count billions away is billions of cycles to run first;
- the sound processor (``SND``: the SPC700's RAM and registers, then the DSP's
  state): the opcode the SPC700 is in (a byte) and its step within it (the
  core's multi-step opcodes have 2 to 5 steps, and a step past the last one
  matches nothing, so the SPC700 spins without time passing); each voice's
  position in its 12-sample BRR buffer (a multiple of 4 below 12) and its
  interpolation position (below 0x8000), which index that 24-entry buffer
  (the raw core dies with SIGSEGV); and the padding after each voice and the
  DSP's state, a count of bytes to skip that the core writes as 0 and reads
  on past the block by.

A Super FX cartridge's state adds its chip's block (``SFX``), whose pointers
the core rebuilds as a base it holds plus a 4-byte offset from the state: the
current registers, the screen's columns, the RAM and ROM banks and the cache,
each of which the core only ever points inside its registers, RAM, ROM or
cache; and its plot mode, which picks the function the core then calls from a
table of 10 (the core writes ``SCMR & 3``). A wild offset or mode is a wild
pointer, or a call through one, as in Genesis Plus GX's bank map.

The PPU, DMA and the memories are masked where they are used, so they need
no check (fuzzing their blocks in Skipper-Snes's states killed no core).
"""

from __future__ import annotations

import struct

SNES9X_MAGIC = b"#!s9xsnp:"
HEADER = len(SNES9X_MAGIC) + 5  # the 4-digit version and a newline
VERSION = 9
"""The newest state version stable-retro's snes9x reads (its ``SNAPSHOT_VERSION``)."""
H_MAX = 1364
"""Master cycles of a line (``SNES_CYCLES_PER_SCANLINE``); the short line has one dot (4 cycles) less."""
V_MAX = (262, 312)
"""Lines of an NTSC and a PAL frame (one more in an interlaced field)."""
CYCLES = 1 << 23
"""The furthest the CPU's clock or the SPC700's may be from the line's start: far above a frame's DMA, far below
the billions a wild value asks the core to run first."""

# Each block's fields, in the core's order and sizes (>: big-endian), from snapshot.cpp's SnapCPU and SnapTimings.
CPU_FIELDS = (
    ">iiiIiiiiBBBBBBiBBBBBB",
    (
        "Cycles PrevCycles V_Counter Flags IRQPending MemSpeed MemSpeedx2 FastROMSpeed InDMA InHDMA InDMAorHDMA "
        "InWRAMDMAorHDMA HDMARanInDMA WhichEvent NextEvent WaitingForInterrupt NMILine IRQLine IRQTransition "
        "IRQLastState IRQExternal"
    ),
)
TIM_FIELDS = (
    ">iiiiiiiiiiiBiiiiiB",
    (
        "H_Max_Master H_Max V_Max_Master V_Max HBlankStart HBlankEnd HDMAInit HDMAStart NMITriggerPos "
        "WRAMRefreshPos RenderPos InterlaceField DMACPUSync NMIDMADelay IRQPendCount APUSpeedup IRQTriggerCycles "
        "APUAllowTimeOverflow"
    ),
)
LINE_EVENTS = ("HBlankStart", "HBlankEnd", "HDMAInit", "HDMAStart", "WRAMRefreshPos", "RenderPos")
DELAYS = ("DMACPUSync", "NMIDMADelay", "IRQTriggerCycles", "IRQPendCount")
"""Cycle counts the core adds to its clock or counts down (it sets them to 18 or 20, 24, 10, 0 or 2)."""
EVENTS = range(1, 7)
"""The H-events the core handles (``HC_HBLANK_START_EVENT`` to ``HC_WRAM_REFRESH_EVENT``)."""
FAST_ROM = (6, 8)
"""The fast ROM's access times the core sets (``ONE_CYCLE``, ``SLOW_ONE_CYCLE``)."""

SPC_RAM = 0x10000
SMP_INTS = 41
"""The SPC700's state after its RAM: 41 little-endian 32-bit numbers (its clock, opcode, step, registers, timers)."""
SPC700_STEPS = {
    0x8F: 3, 0xAA: 2, 0xAF: 2, 0xBA: 3, 0xBF: 2, 0xC4: 3, 0xC5: 4, 0xC6: 3, 0xC7: 5, 0xC9: 4, 0xCA: 3, 0xCB: 3,
    0xCC: 4, 0xD4: 3, 0xD5: 3, 0xD6: 3, 0xD7: 5, 0xD8: 3, 0xD9: 3, 0xDA: 4, 0xDB: 3, 0xE4: 2, 0xE5: 3, 0xE6: 2,
    0xE7: 4, 0xE8: 2, 0xE9: 2, 0xEB: 2, 0xEC: 2, 0xF4: 2, 0xF5: 2, 0xF6: 2, 0xF7: 4, 0xF8: 2, 0xF9: 2, 0xFA: 4,
}  # fmt: skip
"""The SPC700's opcodes the core runs in steps (its pseudo-cycle core), and their steps; every other opcode is one."""
DSP_REGISTERS = 128
VOICES = 8
BRR_BUFFER = 12
VOICE_FIXED = 2 * BRR_BUFFER + 8 + 5
"""A voice's bytes before its padding count: its BRR buffer, then interpolation position, BRR address, envelope,
hidden envelope (2 bytes each), then its buffer position, BRR offset, key-on delay, envelope mode, ENVX (1 each)."""
ECHO_HISTORY = 8 * 2 * 2
DSP_MISC = 49
"""The DSP's bytes after the echo history, before its last padding count."""


# The Super FX's block (SFX, snapshot.cpp's SnapFX): where its fields are, and the pointers the core rebuilds from
# 4-byte offsets (big-endian) added to a base it holds, unchecked.
SFX_BANK_REGISTERS = {"vPrgBankReg": 76, "vRomBankReg": 80}
SFX_MODE = 155
"""``vMode``: the plot mode, which indexes the table of plot functions the core calls (it writes ``SCMR & 3``)."""
SFX_REGISTER_POINTERS = (100, 104)
"""``pvDreg``, ``pvSreg``: offsets into the 16 registers (4 bytes each)."""
SFX_RAM_POINTERS = (163, *range(167, 167 + 32 * 4, 4), 439, *range(451, 451 + 4 * 4, 4))
"""``pvScreenBase``, ``apvScreen[32]``, ``pvRamBank``, ``apvRamBank[4]``: offsets into the Super FX's RAM."""
SFX_RAM_REACH = 0x3FC00 + 0xBC00
"""The furthest into its RAM the core itself points: a screen base of ``SCBR << 10`` and a column past it."""
SFX_ROM_POINTERS = {"vPrgBankReg": 447, "vRomBankReg": 443}
"""``pvPrgBank``, ``pvRomBank``: offsets into the ROM (of 64 KiB banks, the upper half 2 MiB on) while their bank
register names a ROM bank (below 0x70; banks 0x70 to 0x73 are its RAM, at no fixed offset from the ROM)."""
SFX_ROM_REACH = 0x400000
SFX_CACHE = (468, 0x100)
"""``pvCache``: the cache's offset in the Super FX's registers, which the core only ever sets to 0x100."""
SFX_SIZE = 996


def _superfx_problem(sfx: bytes) -> str:
    sfx = sfx[:SFX_SIZE].ljust(SFX_SIZE, b"\0")

    def word(at: int) -> int:
        return int.from_bytes(sfx[at : at + 4], "big")

    if word(SFX_MODE) > 3:
        return f"SFX plot mode {word(SFX_MODE)}"
    if any(word(at) >= 16 * 4 or word(at) % 4 for at in SFX_REGISTER_POINTERS):
        return f"SFX register pointers {[word(at) for at in SFX_REGISTER_POINTERS]}"
    if wild := [hex(word(at)) for at in SFX_RAM_POINTERS if word(at) >= SFX_RAM_REACH]:
        return f"SFX RAM pointer {wild[0]}"
    for register, at in SFX_ROM_POINTERS.items():
        if word(SFX_BANK_REGISTERS[register]) < 0x70 and word(at) >= SFX_ROM_REACH:
            return f"SFX ROM pointer {word(at):#x}"
    at, offset = SFX_CACHE
    return f"SFX cache pointer {word(at):#x}" if word(at) != offset else ""


def snes9x_blocks(state: bytes) -> dict[bytes, bytes]:
    """Each block of ``state`` to its bytes (the first of each name), as far as the blocks read."""
    blocks: dict[bytes, bytes] = {}
    at = HEADER
    while at + 11 <= len(state) and state[at + 3 : at + 4] in (b":", b"-"):
        if state[at + 4 : at + 5] == b"-":
            length = int.from_bytes(state[at + 6 : at + 10], "big")
        elif state[at + 4 : at + 10].isdigit():
            length = int(state[at + 4 : at + 10])
        else:
            break
        blocks.setdefault(state[at : at + 3], state[at + 11 : at + 11 + length])
        at += 11 + length
    return blocks


def _fields(block: bytes, spec: tuple[str, str]) -> dict[str, int]:
    """A struct block's fields, as the core reads them: the block cut or zero-filled to the struct's size."""
    fmt, names = spec
    size = struct.calcsize(fmt)
    return dict(zip(names.split(), struct.unpack(fmt, block[:size].ljust(size, b"\0")), strict=True))


def _timing_problem(tim: dict[str, int], cpu: dict[str, int]) -> str:
    lines = tim["V_Max_Master"]
    wrong = [
        (f"TIM H_Max_Master {tim['H_Max_Master']}", tim["H_Max_Master"] != H_MAX),
        (f"TIM H_Max {tim['H_Max']}", tim["H_Max"] not in (H_MAX - 4, H_MAX)),
        (f"TIM V_Max_Master {lines}", lines not in V_MAX),
        (f"TIM V_Max {tim['V_Max']}", tim["V_Max"] not in (lines, lines + 1)),
        *((f"TIM {name} {tim[name]}", not 0 <= tim[name] < H_MAX) for name in (*LINE_EVENTS, *DELAYS)),
        (f"CPU WhichEvent {cpu['WhichEvent']}", cpu["WhichEvent"] not in EVENTS),
        (f"CPU V_Counter {cpu['V_Counter']}", not 0 <= cpu["V_Counter"] <= tim["V_Max"]),
        (f"CPU FastROMSpeed {cpu['FastROMSpeed']}", cpu["FastROMSpeed"] not in FAST_ROM),
        *((f"CPU {name} {cpu[name]}", abs(cpu[name]) > CYCLES) for name in ("Cycles", "PrevCycles", "NextEvent")),
    ]
    return next((what for what, bad in wrong if bad), "")


def _sound_problem(snd: bytes) -> str:
    snd = snd.ljust(SPC_RAM + 1024, b"\0")
    clock, opcode, step = struct.unpack_from("<iii", snd, SPC_RAM)
    if abs(clock) > CYCLES:
        return f"SND SPC700 clock {clock}"
    if not 0 <= opcode <= 0xFF or not 0 <= step < SPC700_STEPS.get(opcode, 1):
        return f"SND SPC700 opcode {opcode:#x} at step {step}"
    at = SPC_RAM + 4 * SMP_INTS + DSP_REGISTERS
    for voice in range(VOICES):
        (interpolation,) = struct.unpack_from("<H", snd, at + 2 * BRR_BUFFER)
        position, padding = snd[at + 2 * BRR_BUFFER + 8], snd[at + VOICE_FIXED]
        if position >= BRR_BUFFER or position % 4 or interpolation >= 0x8000 or padding:
            return f"SND voice {voice} BRR position {position}, interpolation {interpolation:#x}, padding {padding}"
        at += VOICE_FIXED + 1
    padding = snd[at + ECHO_HISTORY + DSP_MISC]
    return f"SND DSP padding {padding}" if padding else ""


def snes9x_problem(state: bytes) -> str:
    """Why snes9x would index outside its memory, or never return, with ``state`` (``""`` when it would not)."""
    if not state.startswith(SNES9X_MAGIC) or not state[9:13].isdigit():
        return ""
    version = int(state[9:13])
    blocks = snes9x_blocks(state)
    if not 7 <= version <= VERSION or any(name not in blocks for name in (b"CPU", b"TIM", b"SND")):
        return ""  # older layouts, or a state the core refuses whole
    wrong = _timing_problem(_fields(blocks[b"TIM"], TIM_FIELDS), _fields(blocks[b"CPU"], CPU_FIELDS))
    if not wrong and version >= 8:  # the sound block's layout since snes9x took bsnes's SPC700
        wrong = _sound_problem(blocks[b"SND"])
    if not wrong and b"SFX" in blocks:
        wrong = _superfx_problem(blocks[b"SFX"])
    if not wrong:
        return ""
    return (
        f"its {wrong} is outside what the core itself writes (its timings, clocks and sound-chip positions), "
        "so the core indexes memory it does not own or never ends a frame"
    )
