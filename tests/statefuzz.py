"""Fuzzing our cartridges' states core by core, and running each on the raw core (no check) in one child.

Each core's mutator knows where its loader reads structure (names, sizes) and
small values (registers, counters, times), so a few dozen states reach what a
random byte in a 64 KiB VRAM never would. The raw run forks once per state in
one child: a state that kills or hangs the core ends only its fork (an alarm
ends a hang), and the child prints each state's end as one JSON line.
"""

from __future__ import annotations

import json
import random
import struct
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from childproc import REPO, run_child

from retrokit.data.states import read_state
from retrokit.host.gblayout import gambatte_entries
from retrokit.host.pcelayout import mednafen_sections
from retrokit.host.sneslayout import HEADER, SPC_RAM


def _pce(rng: random.Random, good: bytes) -> bytes:
    sections = mednafen_sections(good) or {}
    small = [(at, size) for variables in sections.values() for _, at, size in variables if size <= 8]
    state = bytearray(good)
    for _ in range(rng.randint(1, 3)):
        at, size = rng.choice(small)
        state[at : at + size] = rng.randbytes(size)
    return bytes(state)


def _gambatte(rng: random.Random, good: bytes) -> bytes:
    entries = [where for where in (gambatte_entries(good) or {}).values()]
    state = bytearray(good)
    for _ in range(rng.randint(1, 3)):
        at, size = rng.choice(entries)
        if rng.random() < 0.5 and size <= 4:
            state[at : at + size] = rng.randbytes(size)  # a value
        else:
            state[rng.randrange(at - 5, at)] = rng.getrandbits(8)  # its size or its label's end
    return bytes(state)


def _fceumm_entries(good: bytes) -> list[tuple[int, int]]:
    at, found = 16, []
    while at + 5 <= len(good):
        (size,) = struct.unpack_from("<I", good, at + 1)
        at, end = at + 5, at + 5 + size
        while at < end:
            (entry,) = struct.unpack_from("<I", good, at + 4)
            found.append((at + 8, entry))
            at += 8 + entry
    return found


def _fceumm(rng: random.Random, good: bytes) -> bytes:
    state = bytearray(good)
    for _ in range(rng.randint(1, 3)):
        at, size = rng.choice(_fceumm_entries(good))
        if rng.random() < 0.5:
            state[at : at + min(size, 8)] = rng.randbytes(min(size, 8))  # a value
        else:  # its size: small or past 2 GiB, as the loader's signed seek reads it
            state[at - 4 : at] = struct.pack("<I", rng.choice([rng.getrandbits(8), 2**32 - rng.randrange(1, 64)]))
    return bytes(state)


def _snes9x(rng: random.Random, good: bytes) -> bytes:
    at, spans = HEADER, {}
    while at + 11 <= len(good) and good[at + 3 : at + 4] == b":":
        length = int(good[at + 4 : at + 10])
        spans[good[at : at + 3]] = (at + 11, length)
        at += 11 + length
    cpu, tim, snd = spans[b"CPU"], spans[b"TIM"], spans[b"SND"]
    regions = [cpu, tim, (snd[0] + SPC_RAM, snd[1] - SPC_RAM)]  # the sound block past the SPC700's RAM
    state = bytearray(good)
    for _ in range(rng.randint(1, 3)):
        start, length = rng.choice(regions)
        state[start + rng.randrange(length)] = rng.choice([0x00, 0x7F, 0x80, 0xFF, rng.getrandbits(8)])
    return bytes(state)


@dataclass(frozen=True)
class Fuzz:
    """One core's fuzz: the cartridge, the state it mutates, and how.

    Attributes:
        system: The system's name.
        game: The cartridge's folder under games/.
        state: The state file it mutates.
        rom: The ROM's file name.
        mutate: Makes a mutated copy of the state.
        count: How many copies the tests fuzz: enough for the fixed seed to kill the raw core (a SNES state that
            hangs it costs the whole alarm, so fewer there).
    """

    system: str
    game: str
    state: str
    rom: str
    mutate: Callable[[random.Random, bytes], bytes]
    count: int = 40

    def states(self, count: int | None = None, seed: int = 42) -> list[bytes]:
        """``count`` (by default :attr:`count`) mutated copies of the state, the same for the same seed."""
        good = read_state(REPO / "games" / self.game / self.state)
        rng = random.Random(seed)
        return [self.mutate(rng, good) for _ in range(self.count if count is None else count)]


FUZZES = {
    "PCEngine": Fuzz("PCEngine", "Skipper-PCEngine", "Level1.state", "rom.pce", _pce),
    "GameBoy": Fuzz("GameBoy", "Trekker-GameBoy", "Level1.state", "rom.gb", _gambatte),
    "Nes": Fuzz("Nes", "Hopper-Nes", "Level1-1.state", "rom.nes", _fceumm),
    "Snes": Fuzz("Snes", "Skipper-Snes", "Level1.state", "rom.sfc", _snes9x, count=24),
}

RAW_RUN = """
import json, os, random, signal, sys
from retrokit.data import probe
from retrokit.host.emulator import Emulator

for system, rom, paths in json.load(open(JOBS)):
    emu = Emulator(system, rom)
    for path in paths:
        data = open(path, "rb").read()
        pid = os.fork()
        if pid == 0:
            os.dup2(os.open(os.devnull, os.O_WRONLY), 1)  # the cores print; only the parent's lines count
            signal.alarm(HANG_SECONDS)
            state = probe._mint(data, system)  # unchecked, on purpose: the raw core
            emu.set_state(state)
            rng = random.Random(0)
            for _ in range(FRAMES // 10):
                emu.run([rng.getrandbits(12) for _ in range(emu.ports)], 10)
            emu.set_state(state)
            emu.run(0, 1)
            os._exit(0)
        _, status = os.waitpid(pid, 0)
        died = signal.Signals(os.WTERMSIG(status)).name if os.WIFSIGNALED(status) else None
        print(json.dumps({"path": path, "died": died}), flush=True)
    emu.close()
"""


def run_raw(jobs: list[tuple[str, Path, list[Path]]], folder: Path, frames: int = 120, hang: int = 5) -> dict[str, str]:
    """Run each ``(system, rom, states)`` job's states on the raw core, one fork each, in one child.

    Returns:
        Each state's path to the signal that ended its fork (``SIGALRM``: it hung), for those the core did not survive.
    """
    spec = folder / "raw-jobs.json"
    spec.write_text(json.dumps([(system, str(rom), [str(p) for p in paths]) for system, rom, paths in jobs]))
    code = f"JOBS = {str(spec)!r}\nFRAMES = {frames}\nHANG_SECONDS = {hang}\n" + RAW_RUN
    count = sum(len(paths) for *_, paths in jobs)
    child = run_child(code, timeout=60 + count * 2, env={"RETROKIT_DATA": str(folder / "data")})
    assert child.returncode == 0, child.describe()
    ends = [json.loads(line) for line in child.stdout.splitlines() if line.startswith("{")]
    assert len(ends) == count, child.describe()
    return {end["path"]: end["died"] for end in ends if end["died"]}
