"""Skipping the drawing of frames nobody sees changes nothing an agent gets.

The host tells a core, through libretro's GET_AUDIO_VIDEO_ENABLE, which
frames of a step are seen; the Genesis Plus GX that ``retrokit build-core``
makes then skips drawing the others. The wheel's core never asks. These tests
run the patched core, skipping, against the wheel's core, which draws every
frame, on the same random inputs: RAM, rewards, dones, infos and observed
frames must all be equal. They skip when the patched core is not built.
"""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

import retrokit
from retrokit.data.games import find_game
from retrokit.errors import InvalidArgumentError
from retrokit.host.cores import CORES_ENV, built_core
from retrokit.host.emulator import Emulator
from retrokit.host.statelayout import GENESIS_Z80_BANK

# How long each run plays: until a number of episodes have ended and the env has played TAIL steps after the last
# reset, within a cap that fails the test if they have not (so every run includes a reset). Measured on these
# seeds: from every Dasher state the first episode ends (player 1 loses a life) after 250 to 435 steps, and the
# camera's and the players' furthest x over 1,000 steps are reached within that first episode (but 1 pixel on
# Zone3.Act1.2P), so the steps after it draw again the screens already compared; the cap is the 500 steps this test
# played before. Airstriker's random play loses its three lives in 328 to 388 steps, each episode from Level1's start
# (7 episodes in the 2,500 steps this test played before, the longest the second): three episodes play as far into
# the level, with two resets and new enemies, shots and explosions each time, and the cap is those 2,500 steps.
TAIL = 10
DASHER_STEPS = 500
AIRSTRIKER_STEPS = 2_500
VECTOR_STEPS = 120  # two truncations at max_episode_steps=50 in each env, each followed by its autoreset
FRAMESKIP = 4
Z80_RAM = slice(16 + 0x10000, GENESIS_Z80_BANK - 1)  # in a Genesis state: 8 KiB after the work RAM
DASHER_STATES = find_game("Dasher-Genesis").states


@pytest.fixture(scope="module")
def patched():
    """The built, patched Genesis Plus GX (in the data folder), or a skip saying how to build it."""
    found = built_core("genesis_plus_gx")
    if found is None:
        pytest.skip("the patched Genesis Plus GX is not built: run `retrokit build-core genesis_plus_gx` (CI does)")
    return found.path


def make_env(monkeypatch: pytest.MonkeyPatch, core, game: str, state: str | None = None, **options):
    """An env whose Genesis core is ``core`` (RETROKIT_CORES comes first in the search)."""
    monkeypatch.setenv(CORES_ENV, str(core.parent))
    players = 2 if state is not None and state.endswith(".2P") else 1
    env = retrokit.make(game, state, frameskip=FRAMESKIP, sticky_prob=0.25, players=players, **options)
    assert env.emulator.rom and env.emulator.space  # made with the core above
    return env


def play_both(skipping: gymnasium.Env, drawing: gymnasium.Env, steps: int, seed: int, episodes: int) -> None:
    """Step both envs with the same random actions until ``episodes`` have ended and TAIL steps more, asserting they
    agree on everything, and that this came within ``steps``."""
    space = skipping.action_space
    space.seed(seed)
    a, info_a = skipping.reset(seed=seed)
    b, info_b = drawing.reset(seed=seed)
    assert (a == b).all() and info_a == info_b
    ended, tail = 0, TAIL
    for step in range(steps):
        if ended >= episodes:
            if tail == 0:
                return
            tail -= 1
        action = space.sample()
        a, ra, ta, ua, info_a = skipping.step(action)
        b, rb, tb, ub, info_b = drawing.step(action)
        ram_a, ram_b = skipping.unwrapped.emulator.ram, drawing.unwrapped.emulator.ram
        assert (ram_a == ram_b).all(), f"RAM differs at step {step}, bytes {np.flatnonzero(ram_a != ram_b)[:8]}"
        assert (ra, ta, ua) == (rb, tb, ub), f"reward or done differs at step {step}"
        assert info_a == info_b, f"info differs at step {step}"
        assert (a == b).all(), f"observation differs at step {step}"
        if ta or ua:
            ended += 1
            a, info_a = skipping.reset()
            b, info_b = drawing.reset()
            assert (a == b).all() and info_a == info_b
    raise AssertionError(f"{steps} steps ended {ended} of the {episodes} episodes (and {TAIL} steps after) meant")


def test_the_wheel_core_never_asks_and_the_patched_one_asks_every_frame(patched, wheel, dasher_rom) -> None:
    for core, asks in ((wheel, False), (patched, True)):
        emu = Emulator("Genesis", dasher_rom, core_path=core)
        emu.run(0, 10)
        assert (emu.av_asked == 10) if asks else (emu.av_asked == 0)
        emu.close()


def test_frames_not_seen_are_not_drawn(patched, dasher_rom) -> None:
    """The skipping is real: told no frame is seen, the core leaves its picture as it was."""
    emu = Emulator("Genesis", dasher_rom, core_path=patched)
    emu.run(0, 300)  # past the title's first frames, onto a moving picture
    shown = emu.screen()
    emu.set_video_frames("none")
    emu.run(0, 60)
    assert (emu.screen() == shown).all()
    emu.set_video_frames("last")
    emu.run(0, 60)
    assert not (emu.screen() == shown).all()
    emu.close()


def test_video_frames_must_be_a_known_mode(airstriker) -> None:
    with pytest.raises(InvalidArgumentError, match=r"'all', 'last' or 'none', got 'lats'\. Did you mean 'last'\?"):
        airstriker.set_video_frames("lats")


# With screens, every step's last frame is drawn and compared: the full run. With RAM observations no frame is
# drawn at all, which is what that run adds, through the env, for one episode and its reset; test_sound_skip.py
# plays Airstriker 6,000 frames more on the emulator drawing no frame (and making no sound) against the wheel's core.
@pytest.mark.parametrize(("obs_type", "episodes"), [("rgb", 3), ("ram", 1)], ids=["rgb", "ram"])
def test_airstriker_plays_the_same_skipping_as_drawing(
    monkeypatch, patched, wheel, obs_type: str, episodes: int
) -> None:
    skipping = make_env(monkeypatch, patched, "Airstriker-Genesis", obs_type=obs_type)
    drawing = make_env(monkeypatch, wheel, "Airstriker-Genesis", obs_type=obs_type)
    play_both(skipping, drawing, AIRSTRIKER_STEPS, seed=1, episodes=episodes)
    assert skipping.emulator.av_asked and not drawing.emulator.av_asked  # the envs ran the cores meant
    skipping.close()
    drawing.close()


@pytest.mark.parametrize("state", DASHER_STATES)
def test_dasher_plays_the_same_skipping_as_drawing(monkeypatch, patched, wheel, state: str) -> None:
    """Also the sound skipping's check for every Dasher state (test_sound_skip.py): the env clears the audio bit,
    and the Z80's RAM (where a sound driver would keep what it read from the chips) ends equal too."""
    skipping = make_env(monkeypatch, patched, "Dasher-Genesis", state)
    drawing = make_env(monkeypatch, wheel, "Dasher-Genesis", state)
    play_both(skipping, drawing, DASHER_STEPS, seed=2, episodes=1)
    z80 = [bytes(env.unwrapped.emulator.get_state())[Z80_RAM] for env in (skipping, drawing)]
    assert z80[0] == z80[1], "the Z80's RAM differs at the end"
    skipping.close()
    drawing.close()


@pytest.mark.parametrize("skip_video", [True, False], ids=["skipping", "turned-off"])
def test_skipping_can_be_turned_off(monkeypatch, patched, skip_video: bool) -> None:
    """With RAM observations nobody sees a frame: the core draws none, unless skip_video=False."""
    env = make_env(monkeypatch, patched, "Dasher-Genesis", obs_type="ram", skip_video=skip_video)
    env.emulator.reset()  # power on: the title screen moves by itself
    env.emulator.run(0, 300)
    shown = env.emulator.screen()
    env.emulator.run(0, 60)
    assert (env.emulator.screen() == shown).all() == skip_video
    env.close()


def test_the_vector_env_plays_the_same_skipping_as_drawing(monkeypatch, patched, wheel) -> None:
    options = {"frameskip": FRAMESKIP, "sticky_prob": 0.25, "max_episode_steps": 50}
    monkeypatch.setenv(CORES_ENV, str(patched.parent))
    skipping = retrokit.make_vec("Dasher-Genesis", 2, **options)
    monkeypatch.setenv(CORES_ENV, str(wheel.parent))
    drawing = retrokit.make_vec("Dasher-Genesis", 2, **options)
    a, _ = skipping.reset(seed=3)
    b, _ = drawing.reset(seed=3)
    assert (a == b).all()
    space = skipping.action_space
    space.seed(3)
    truncations = np.zeros(2, dtype=int)
    for step in range(VECTOR_STEPS):
        actions = space.sample()
        a, ra, ta, ua, info_a = skipping.step(actions)
        b, rb, tb, ub, info_b = drawing.step(actions)
        truncations += ua
        for i in range(2):
            assert (skipping.envs[i].emulator.ram == drawing.envs[i].emulator.ram).all(), f"env {i} step {step}"
        assert (a == b).all() and (ra == rb).all() and (ta == tb).all() and (ua == ub).all(), f"step {step}"
        assert all((info_a[k] == info_b[k]).all() for k in info_a if not k.startswith("_")), f"step {step}"
    assert (truncations >= 2).all(), f"expected two truncations and autoresets in each env, got {truncations}"
    assert all(env.emulator.av_asked for env in skipping.envs) and not drawing.envs[0].emulator.av_asked
    skipping.close()
    drawing.close()
