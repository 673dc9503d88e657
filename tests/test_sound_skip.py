"""Skipping the sound nobody hears changes nothing the game can observe.

The Genesis Plus GX that ``retrokit build-core`` makes skips sound synthesis
on frames whose audio bit of GET_AUDIO_VIDEO_ENABLE is clear (an env without
audio capture clears it on every frame): the YM2612 runs only its timers,
their status and CSM, the PSG and the FM clock move on without making
samples. These tests run it, skipping video and sound, against the wheel's
core, which makes both, on the same random buttons: the 68000's RAM, the
Z80's RAM (where a sound driver keeps what it read from the chips) and what
the chips hold that the CPUs can read or that times it (the YM2612's status,
mode and timers, the PSG, the FM clock: compared directly in the state, so a
drift shows at the first comparison) must stay equal, in Airstriker's music
and under a Z80 program that runs the YM2612's timers; a state saved by the
skipping core must play on in the wheel's core and in stable-retro exactly as
the wheel's own; movies recorded with skipping must play back without it, and
the reverse. They skip when the patched core is not built.
"""

from __future__ import annotations

import gzip
import importlib
import importlib.util
import struct
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pytest

import retrokit
from retrokit.data.games import find_game
from retrokit.data.statecheck import vet_state
from retrokit.host import build
from retrokit.host.cores import CORES_ENV, built_core, stable_retro_version
from retrokit.host.emulator import Emulator
from retrokit.host.statelayout import GENESIS_BANK_MAP, GENESIS_FIFO_INDEX, GENESIS_SIGNATURE, GENESIS_Z80_BANK
from retrokit.movie.bk2 import read_bk2
from retrokit.movie.playback import replay

# Where Genesis Plus GX 1.7.5 keeps, in a Mega Drive state, what its sound chips hold that the CPUs can read or that
# decides when they change (its state_save, sound_context_save, YM2612SaveContext, psg_context_save): after the VDP's
# context (which ends 26 bytes after its FIFO index) comes the YM2612's whole C struct (3,576 bytes as the x86-64 C
# ABI lays it out: six channels of 400 bytes, the DAC, then the OPN unit whose first member is FM_ST: address, status,
# mode, fn_h, then the timers' TA, TAL, TAC, TB, TBL, TBC as 4-byte ints, then the 8x32 detune table; then FM_3SLOT,
# whose key_csm is the CSM key timer A drives); then 24 one-byte detune indexes, each followed by a byte the core
# skips (YM2612SaveContext advances its offset twice); then the PSG's 156 bytes (its clock, latch, noise shift
# register, registers, frequency counters, polarities, pending deltas and outputs); then the FM clock
# (fm_cycles_start, 4 bytes). The 68000's 90 bytes and the Z80's 88 then end at the bank map (GENESIS_BANK_MAP), which
# checks the sum; chip_state checks the fields.
YM = GENESIS_FIFO_INDEX + 26
YM_TIMERS = YM + 2408  # FM_ST
YM_KEY_CSM = YM_TIMERS + 1060 + 28
PSG = YM + 3576 + 48
FM_CLOCK = PSG + 156
assert FM_CLOCK + 4 + 90 + 88 == GENESIS_BANK_MAP
SLOT_PHASES = [YM + channel * 400 + slot * 80 + 36 for channel in range(6) for slot in range(4)]


def chip_state(state: bytes) -> dict[str, int | bytes]:
    """What the CPUs can read of the sound chips (the YM2612's status, timers and mode; the PSG is write-only but
    its counters decide its future), and the FM clock that times them, by name; checked to be where it is read."""
    _address, status, mode, _fn_h, ta, tal, tac, tb, tbl, tbc = struct.unpack_from("<HBxIB3xiiiiii", state, YM_TIMERS)
    detune = struct.unpack_from("<256i", state, YM_TIMERS + 36)
    assert state[:16] == GENESIS_SIGNATURE and tal == 1024 - ta and tbl == (256 - tb) << 4, "not an FM_ST here"
    assert detune[32:64] == tuple(-d for d in detune[160:192]) and any(detune[32:64]), "not the detune table here"
    return {"YM status": status, "YM mode": mode, "timer A": ta, "timer A counter": tac, "timer B": tb,
            "timer B counter": tbc, "CSM key": state[YM_KEY_CSM], "PSG": state[PSG:FM_CLOCK],
            "FM clock": state[FM_CLOCK:FM_CLOCK + 4]}  # fmt: skip


# Frames from each state, and the frame at which the skipping core's state is saved and loaded into the wheel's core
# and into stable-retro, which play on beside the wheel's own from there. Airstriker is the only game here with a
# sound driver: its Z80 plays music through the YM2612 and the PSG. Measured over 20,000 frames of this play, it never
# starts the YM2612's timers (mode 0, both counters 0 throughout: a started counter never returns to 0), so no length
# of play lets a timer drift reach the RAM: a Z80 program planted in a Dasher state runs them instead (TIMER_PROGRAM
# below). The chips' state above is compared directly, with the Z80's RAM, every Z80_EVERY runs, where any
# difference in what the CPUs can read, in the PSG or in the FM clock shows at once (a core built to move the FM
# clock, or the PSG's tone edges, one step off while skipping fails at frame 4; the RAM alone let both through 20,000
# frames). The 6,000 frames (100 s of game) cover the level's music and sound effects under random play; by the save
# at 2,000 the FM channels' phases (which skipping leaves standing) are asserted to have moved apart, so the loaded
# state carries a synthesis the wheel never made. Dasher has no sound (tools/testcart/src/main.c parks the Z80 on "di;
# halt", silences the PSG and never writes the YM): from its states, skipping has no sound to change and only has to
# leave the game alone, which a change of frame timing would show within frames. test_video_skip.py shows that for
# every Dasher state, through an env on the same skipping core (whose env clears the audio bit too) against the
# wheel's, comparing the RAM at every step and the Z80's RAM at the end; here Dasher plays on the emulator directly
# from the one state, with its game to carry over the save.
FRAMES = {"Airstriker-Level1": (6_000, 2_000), "Dasher-Zone2.Act1": (1_500, 500)}
RUN = 4  # frames a run, each with new random buttons
Z80_EVERY = 25  # runs between comparisons of the Z80's RAM and the chips (a state is 1 MB)
WORK_RAM = slice(16, 16 + 0x10000)  # after the state's 16-byte signature
Z80_RAM = slice(16 + 0x10000, GENESIS_Z80_BANK - 1)  # 8 KiB, then the Z80's bus state and bank
DASHER = "Dasher-Genesis"
DASHER_STATES = find_game(DASHER).states


@pytest.fixture(scope="module")
def patched():
    """The built Genesis Plus GX with today's patch (which skips sound), or a skip saying how to build it."""
    found = built_core("genesis_plus_gx")
    current = build.up_to_date(build.recipe_for("genesis_plus_gx"), stable_retro_version() or "")
    if found is None or current is None:
        pytest.skip("the patched Genesis Plus GX is not built with today's patch: run `retrokit build-core genesis_plus_gx`")
    return found.path


def starts(airstriker_dir) -> dict[str, tuple]:
    """Every state with a ROM here: (rom, state bytes)."""
    rom = airstriker_dir / "rom.md"
    level1 = airstriker_dir / "Level1.state"
    found = {"Airstriker-Level1": (rom, vet_state(gzip.decompress(level1.read_bytes()), "Genesis", rom, shipped=level1))}
    dasher = find_game(DASHER)
    for state in DASHER_STATES:
        path = dasher.state_path(state)
        found[f"Dasher-{state}"] = (dasher.rom_path(), vet_state(gzip.decompress(path.read_bytes()), "Genesis", dasher.rom_path(), shipped=path))
    return found


START_NAMES = ["Airstriker-Level1", *(f"Dasher-{state}" for state in DASHER_STATES)]


def pair(patched, wheel, rom, state) -> tuple[Emulator, Emulator]:
    """The patched core told that no frame is seen or heard, and the wheel's core, at the same state."""
    skipping, making = Emulator("Genesis", rom, core_path=patched), Emulator("Genesis", rom, core_path=wheel)
    skipping.set_state(state)
    making.set_state(state)
    skipping.set_video_frames("none")
    return skipping, making


class StableRetro:
    """stable-retro's own emulator (its host, the wheel's core) run as the lanes below run ours."""

    def __init__(self, stable_retro, making: Emulator, state: bytes) -> None:
        self.env = stable_retro.make(
            "Airstriker-Genesis-v0", render_mode=None, use_restricted_actions=stable_retro.Actions.ALL
        )
        self.env.reset(seed=0)
        self.em = self.env.unwrapped.em
        self.em.set_state(state)
        self.buttons = list(self.env.unwrapped.buttons)
        self.system = making.system
        assert self.system.mask(self.buttons) == (1 << 12) - 1, "stable-retro must get every button ours get"

    def run(self, buttons: np.ndarray, frames: int) -> None:
        for player, mask in enumerate(buttons):
            names = self.system.buttons_of(int(mask))
            self.em.set_button_mask(np.array([b in names for b in self.buttons], dtype=np.uint8), player)
        for _ in range(frames):
            self.em.step()

    @property
    def ram(self) -> np.ndarray:
        return np.frombuffer(self.em.get_state(), dtype=np.uint8)[WORK_RAM]

    def get_state(self) -> bytes:
        return self.em.get_state()

    def close(self) -> None:
        self.env.close()


def play(making: Emulator, lanes: dict, frames: int, seed: int, joining=None) -> dict[str, str | None]:
    """Run the wheel's core and every lane on the same random buttons (both pads), comparing each lane's RAM with
    the wheel core's every run, and its Z80 RAM and chip state every Z80_EVERY runs. ``joining`` is (frame, function
    of the lanes returning new lanes) to add lanes mid-play. Returns each lane's first difference (None: none)."""
    rng = np.random.default_rng(seed)
    differs: dict[str, str | None] = dict.fromkeys(lanes)
    for run in range(frames // RUN):
        if joining is not None and run * RUN == joining[0]:
            added = joining[1](lanes)
            lanes = {**lanes, **added}
            differs.update(dict.fromkeys(added))
        buttons = rng.integers(0, 1 << 12, size=2).astype(np.uint16)
        making.run(buttons, RUN)
        for emu in lanes.values():
            emu.run(buttons, RUN)
        frame = (run + 1) * RUN
        for name, emu in lanes.items():
            if differs[name] is None and not (emu.ram == making.ram).all():
                differs[name] = f"RAM differs after frame {frame}: {np.flatnonzero(emu.ram != making.ram)[:8]}"
        if run % Z80_EVERY == 0:
            ours = bytes(making.get_state())
            for name, emu in lanes.items():
                theirs = bytes(emu.get_state())
                if differs[name] is None and theirs[Z80_RAM] != ours[Z80_RAM]:
                    differs[name] = f"Z80 RAM differs after frame {frame}"
                chips, reference = chip_state(theirs), chip_state(ours)
                if differs[name] is None and chips != reference:
                    names = [key for key in chips if chips[key] != reference[key]]
                    differs[name] = f"the sound chips' {', '.join(names)} differ after frame {frame}"
    return differs


@dataclass
class Played:
    """One play from a start: each lane's first difference from the wheel's core, and what the skipping core did."""

    differs: dict[str, str | None]
    frames: int
    asked: int
    drawn: int
    phases_apart: bool


def play_from(start: str, patched, wheel, airstriker_dir) -> Played:
    """The skipping core against the wheel's from one start; at the save, the skipping core's state is loaded into
    the wheel's core and (for Airstriker, if installed) into stable-retro, which play on beside them to the end."""
    rom, state = starts(airstriker_dir)[start]
    frames, saved_at = FRAMES[start]
    skipping, making = pair(patched, wheel, rom, state)
    asked, drawn = skipping.av_asked, skipping.av_drawn
    apart, opened = [], [skipping, making]

    def load_the_save(lanes: dict) -> dict:
        saved = skipping.get_state()
        phases = [bytes(state)[at : at + 4] for state in (saved, making.get_state()) for at in SLOT_PHASES]
        apart.append(phases[: len(SLOT_PHASES)] != phases[len(SLOT_PHASES) :])
        reloaded = Emulator("Genesis", rom, core_path=wheel)
        reloaded.set_state(saved)
        opened.append(reloaded)
        added = {"the wheel's core from the save": reloaded}
        if start == "Airstriker-Level1" and importlib.util.find_spec("stable_retro") is not None:
            opened.append(StableRetro(importlib.import_module("stable_retro"), making, bytes(saved)))
            added["stable-retro from the save"] = opened[-1]
        return added

    try:
        joining = (saved_at, load_the_save)
        differs = play(making, {"skipping": skipping}, frames, seed=START_NAMES.index(start), joining=joining)
        return Played(differs, frames, skipping.av_asked - asked, skipping.av_drawn - drawn, apart[0])
    finally:
        for emu in opened:
            emu.close()


@pytest.fixture(scope="module")
def played(patched, wheel, airstriker_dir) -> Callable[[str], Played]:
    """Each start's one play, made when a test first reads it and shared by the tests that check its lanes."""
    done: dict[str, Played] = {}

    def get(start: str) -> Played:
        if start not in done:
            done[start] = play_from(start, patched, wheel, airstriker_dir)
        return done[start]

    return get


@pytest.mark.parametrize("start", list(FRAMES))
def test_ram_and_z80_ram_equal_the_wheel_cores(played, start) -> None:
    run = played(start)
    assert run.differs["skipping"] is None, run.differs["skipping"]
    assert run.asked == run.frames and run.drawn == 0  # every frame asked, none drawn


# A Z80 program that runs the YM2612's timers, as a sound driver timing its music would: timer A every 300 samples
# (TA 724) in CSM mode (which keys channel 3 on and off at each overflow), timer B every 160 (TB 246); it polls the
# status and, at each flag, stores the flags and its 16-bit loop count in a ring at 0x0100, then clears the flags.
# A timer one sample off moves a flag to another iteration of the loop, so the Z80's RAM differs at once: cores built
# to run timer A or timer B one sample short per update, or to leave the CSM key unshifted, while skipping fail at
# frame 4.
TIMER_PROGRAM = bytes.fromhex(
    "F3 310020 210040"  # di; ld sp,0x2000; ld hl,0x4000 (the YM2612's address port; data at 0x4001)
    "3624 23 36B5 2B 3625 23 3600 2B"  # timer A = 0xB5 << 2 | 0 = 724
    "3626 23 36F6 2B"  # timer B = 246
    "3627 23 36BF 2B"  # mode: CSM, flags enabled and cleared, both timers started
    "110001 010000"  # ld de,0x0100; ld bc,0
    "03 7E E603 28FA"  # loop: inc bc; ld a,(hl); and 3; jr z,loop
    "12 13 79 12 13 78 12 13"  # store the flags, c, b at (de)
    "7A FE1F 3802 1601"  # wrap de from 0x1F00 to 0x0100
    "3627 23 36BF 2B 18E3"  # clear the flags (keeping the rest of the mode); jr loop
)
Z80_REGS = GENESIS_BANK_MAP - 88  # Genesis Plus GX's Z80_Regs: pc (4 bytes) first, halt at 56


def timer_state(dasher) -> bytes:
    """Dasher's Zone1.Act1 with the Z80 (which the game parks on "di; halt" and never touches again) running
    TIMER_PROGRAM from 0, checked as any state is."""
    state = bytearray(gzip.decompress(dasher.state_path("Zone1.Act1").read_bytes()))
    z80 = Z80_RAM.start
    state[z80 : z80 + 0x2000] = TIMER_PROGRAM.ljust(0x2000, b"\0")
    assert state[GENESIS_Z80_BANK - 1] == 1 and state[Z80_REGS + 56] == 1, "expected the Z80 running and halted"
    struct.pack_into("<I", state, Z80_REGS, 0)
    state[Z80_REGS + 56] = 0
    return vet_state(bytes(state), "Genesis", dasher.rom_path())


def test_the_ym2612_timers_and_csm_run_the_same_skipping(patched, wheel) -> None:
    dasher = find_game(DASHER)
    skipping, making = pair(patched, wheel, dasher.rom_path(), timer_state(dasher))
    try:
        differs = play(making, {"skipping": skipping}, 1_000, seed=5)
        final = bytes(making.get_state())
    finally:
        skipping.close()
        making.close()
    assert differs["skipping"] is None, differs["skipping"]
    records = final[Z80_RAM][0x100:0x1F00]
    flags = {records[i] for i in range(0, len(records) - 2, 3) if any(records[i : i + 3])}
    assert chip_state(final)["YM mode"] == 0xBF and flags >= {1, 2}, f"the timers did not run: flags {flags}"


def test_the_skipping_core_makes_no_sound_and_the_same_sound_when_asked(patched, wheel, airstriker_dir) -> None:
    """Capturing audio sets the audio bit: then every sample is the wheel core's; without, none is made."""
    rom, state = starts(airstriker_dir)["Airstriker-Level1"]
    skipping, making = pair(patched, wheel, rom, state)
    skipping.set_video_frames("all")
    for emu in (skipping, making):
        emu.capture_audio(True)
        emu.run([0, 0], 600)
    heard, made = skipping.take_audio(), making.take_audio()
    assert len(made) > 600 * 700 and np.abs(made.astype(int)).max() > 0  # Airstriker plays music
    assert np.array_equal(heard, made)
    skipping.capture_audio(False)
    skipping.set_video_frames("none")
    skipping.run([0, 0], 60)
    skipping.capture_audio(True)
    assert len(skipping.take_audio()) == 0  # captured from here on only: the 60 frames made none


@pytest.mark.parametrize("start", list(FRAMES))
def test_a_state_saved_while_skipping_plays_on_in_the_wheels_core(played, start) -> None:
    run = played(start)
    assert run.differs["the wheel's core from the save"] is None, run.differs["the wheel's core from the save"]
    if start == "Airstriker-Level1":  # the save carries a synthesis state the wheel's core never made
        assert run.phases_apart, "the FM operators' phases had not moved apart by the save: nothing was carried over"


def test_a_state_saved_while_skipping_plays_on_in_stable_retro(played) -> None:
    run = played("Airstriker-Level1")
    if "stable-retro from the save" not in run.differs:
        pytest.skip("stable-retro is not installed")
    assert run.differs["stable-retro from the save"] is None, run.differs["stable-retro from the save"]


@pytest.mark.parametrize("direction", ["recorded-skipping", "played-skipping"])
def test_movies_play_back_the_same_with_and_without_skipping(patched, wheel, monkeypatch, tmp_path, direction) -> None:
    """A Dasher movie recorded by an env on one core replays on the other with the RAM the env saw at every step."""
    recording, playing = (patched, wheel) if direction == "recorded-skipping" else (wheel, patched)
    monkeypatch.setenv(CORES_ENV, str(recording.parent))
    env = retrokit.make(DASHER, "Zone1.Act1", frameskip=RUN, sticky_prob=0.25, obs_type="ram", record=str(tmp_path))
    env.reset(seed=7)
    env.action_space.seed(7)
    rams = []
    for _ in range(500):
        env.step(env.action_space.sample())
        rams.append(env.unwrapped.emulator.ram.copy())
    env.close()
    (path,) = tmp_path.glob("*.bk2")
    movie = read_bk2(path)
    assert len(movie.frames) == RUN * len(rams)
    emu = Emulator("Genesis", find_game(DASHER).rom_path(), core_path=playing)
    if playing == patched:
        emu.set_video_frames("none")
    for number in replay(movie, emu, source=str(path)):
        if number and number % RUN == 0:
            step = number // RUN - 1
            assert (emu.ram == rams[step]).all(), f"RAM differs at step {step} of the movie"
