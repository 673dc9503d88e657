"""Skipping the sound nobody hears changes nothing the game can observe.

The Genesis Plus GX that ``retrokit build-core`` makes skips sound synthesis
on frames whose audio bit of GET_AUDIO_VIDEO_ENABLE is clear (an env without
audio capture clears it on every frame): the YM2612 runs only its timers,
their status and CSM, the PSG and the FM clock move on without making
samples. These tests run it, skipping video and sound, against the wheel's
core, which makes both, on the same random buttons: the 68000's RAM and the
Z80's RAM (where a sound driver keeps what it read from the chips) must stay
equal, from every state here; a state saved by the skipping core must play on in the wheel's core
exactly as the wheel's own; movies recorded with skipping must play back
without it, and the reverse. They skip when the patched core is not built.
"""

from __future__ import annotations

import gzip

import numpy as np
import pytest

import retrokit
from retrokit.data.games import find_game
from retrokit.data.statecheck import vet_state
from retrokit.host import build
from retrokit.host.cores import CORES_ENV, built_core, stable_retro_version
from retrokit.host.emulator import Emulator
from retrokit.host.statelayout import GENESIS_Z80_BANK
from retrokit.movie.bk2 import read_bk2
from retrokit.movie.playback import replay

# Frames from each state. Airstriker is the only game here with a sound driver: its Z80 plays music through
# the YM2612 and the PSG, reading the YM's timer and busy flags, which is all the skipped synthesis could change.
# It plays 20,000 frames (5.5 minutes of game, through its looping music), long enough for a slow drift of the
# timers that YM2612UpdateTimers keeps in step to reach the RAM. Dasher has no sound (tools/testcart/src/main.c
# parks the Z80 on "di; halt", silences the PSG and never writes the YM): from its states, skipping has no sound
# to change and only has to leave the game alone, which a change of frame timing would show within frames.
# test_video_skip.py shows that for every Dasher state, through an env on the same skipping core (whose env
# clears the audio bit too) against the wheel's, comparing the RAM at every step and the Z80's RAM at the end;
# here Dasher plays on the emulator directly from the one state the state-saving tests use.
FRAMES = {"Airstriker-Level1": 20_000, "Dasher": 1_000}
RUN = 4  # frames a run, each with new random buttons
Z80_EVERY = 25  # runs between comparisons of the Z80's RAM (a state is 1 MB)
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
#: What the RAM comparison below plays: Airstriker, and one Dasher state (the others: test_video_skip.py).
COMPARED = ["Airstriker-Level1", "Dasher-Zone2.Act1"]


def pair(patched, wheel, rom, state) -> tuple[Emulator, Emulator]:
    """The patched core told that no frame is seen or heard, and the wheel's core, at the same state."""
    skipping, making = Emulator("Genesis", rom, core_path=patched), Emulator("Genesis", rom, core_path=wheel)
    skipping.set_state(state)
    making.set_state(state)
    skipping.set_video_frames("none")
    return skipping, making


def play(emulators: tuple[Emulator, ...], frames: int, seed: int) -> None:
    """Run every emulator on the same random buttons (both pads), asserting their RAM and Z80 RAM stay equal."""
    rng = np.random.default_rng(seed)
    first = emulators[0]
    for run in range(frames // RUN):
        buttons = rng.integers(0, 1 << 12, size=2).astype(np.uint16)
        for emu in emulators:
            emu.run(buttons, RUN)
        for emu in emulators[1:]:
            assert (emu.ram == first.ram).all(), f"RAM differs after frame {(run + 1) * RUN}: {np.flatnonzero(emu.ram != first.ram)[:8]}"
        if run % Z80_EVERY == 0:
            z80 = bytes(first.get_state())[Z80_RAM]
            for emu in emulators[1:]:
                assert bytes(emu.get_state())[Z80_RAM] == z80, f"Z80 RAM differs after frame {(run + 1) * RUN}"


@pytest.mark.parametrize("start", COMPARED)
def test_ram_and_z80_ram_equal_the_wheel_cores(patched, wheel, airstriker_dir, start) -> None:
    rom, state = starts(airstriker_dir)[start]
    frames = FRAMES.get(start, FRAMES["Dasher"])
    skipping, making = pair(patched, wheel, rom, state)
    asked, drawn = skipping.av_asked, skipping.av_drawn
    play((skipping, making), frames, seed=START_NAMES.index(start))
    assert skipping.av_asked - asked == frames and skipping.av_drawn == drawn  # every frame asked, none drawn


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


# Frames played before the save and after it: Airstriker's are long enough for the synthesis state to have moved
# apart; Dasher, with none, has only its game to carry over.
SAVE_FRAMES = {"Airstriker-Level1": (2_000, 4_000), "Dasher-Zone2.Act1": (500, 1_000)}


@pytest.mark.parametrize("start", list(SAVE_FRAMES))
def test_a_state_saved_while_skipping_plays_on_in_the_wheels_core(patched, wheel, airstriker_dir, start) -> None:
    rom, state = starts(airstriker_dir)[start]
    skipping, making = pair(patched, wheel, rom, state)
    before, after = SAVE_FRAMES[start]
    play((skipping, making), before, seed=1)
    saved = skipping.get_state()
    reloaded = Emulator("Genesis", rom, core_path=wheel)
    reloaded.set_state(saved)
    play((making, reloaded), after, seed=2)


def test_a_state_saved_while_skipping_plays_on_in_stable_retro(patched, wheel, airstriker_dir) -> None:
    stable_retro = pytest.importorskip("stable_retro")
    rom, state = starts(airstriker_dir)["Airstriker-Level1"]
    skipping, making = pair(patched, wheel, rom, state)
    play((skipping, making), 2_000, seed=3)
    env = stable_retro.make("Airstriker-Genesis-v0", render_mode=None, use_restricted_actions=stable_retro.Actions.ALL)
    try:
        env.reset(seed=0)
        reference = env.unwrapped
        reference.em.set_state(bytes(skipping.get_state()))
        buttons = list(reference.buttons)
        rng = np.random.default_rng(4)
        for frame in range(2_000):
            mask = int(rng.integers(0, 1 << 12)) & making.system.mask(buttons)
            making.run([mask, 0], 1)
            names = making.system.buttons_of(mask)
            env.step(np.array([b in names for b in buttons], dtype=np.int8))
            theirs = bytes(reference.em.get_state())[WORK_RAM]
            assert theirs == bytes(making.get_state())[WORK_RAM], f"RAM differs {frame + 1} frames after the load"
    finally:
        env.close()


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
