"""The gambatte ``retrokit build-core gambatte`` makes, which skips the sound nobody hears, against the wheel's.

Both cores play Trekker (our Game Boy cartridge, as a Game Boy and as a Game
Boy Color game) from each level's state, on the same random buttons (new ones
every 4 frames) for 3,000 frames in runs of 4: the built core told that only
each run's last frame is seen and no frame is heard (as an RGB env at frame
skip 4 tells it), the wheel's drawing and sounding every frame. After every
run the RAM and the screen are equal, and at the end the whole state. The
built core asks on every frame and is told to draw once a run. With audio
captured, both hand over the same samples. Skipped when the core is not built
(``retrokit build-core gambatte``).
"""

from __future__ import annotations

import numpy as np
import pytest
from skipplay import play_alike

from retrokit.data.games import find_game
from retrokit.data.statecheck import vet_state
from retrokit.data.states import read_state
from retrokit.host.cores import built_core
from retrokit.host.emulator import Emulator
from retrokit.paths import wheel_cores_dir

pytestmark = pytest.mark.skipif(built_core("gambatte") is None, reason="the patched gambatte is not built "
                                "(retrokit build-core gambatte)")

FRAMES = 3000


def _emulated(state: bytes) -> bytes:
    """A gambatte state without its ``dmgpal`` field (the colours a Game Boy Color gives a Game Boy game).

    Saved from memory the core never fills on a Game Boy (it held a heap address), so two of the wheel's own
    cores, opened from the same state and played alike, disagree there and nowhere else.
    """
    at = state.index(b"dmgpal\0") + len(b"dmgpal\0")
    size = int.from_bytes(state[at : at + 3], "big")
    return state[: at + 3] + bytes(size) + state[at + 3 + size :]


def _open(game_name: str, state: str) -> tuple[Emulator, Emulator]:
    """The wheel's gambatte and the built one, each at ``state`` of ``game_name``."""
    game = find_game(game_name)
    rom = game.require_rom()
    path = game.state_path(state)
    data = vet_state(read_state(path), game.system.name, rom, source=str(path))
    wheel = Emulator(game.system.name, rom, core_path=wheel_cores_dir() / "gambatte_libretro.so")
    built = Emulator(game.system.name, rom)  # finds the build in the data folder first
    for emulator in (wheel, built):
        emulator.set_state(data)
    built.set_video_frames("last")
    return wheel, built


@pytest.mark.parametrize("game", ["Trekker-GameBoy", "Trekker-GbColor"])
@pytest.mark.parametrize("state", ["Level1", "Level2", "Level3"])
def test_the_built_gambatte_plays_as_the_wheels_making_no_unheard_sound(game: str, state: str) -> None:
    wheel, built = _open(game, state)
    try:
        buttons = np.random.default_rng(len(state) + len(game)).integers(0, 1 << 8, size=(FRAMES // 4, 1))
        screens = play_alike(wheel, built, buttons)
        assert _emulated(built.get_state()) == _emulated(wheel.get_state())
        assert len(screens) > 10  # the game moved
    finally:
        wheel.close()
        built.close()


def test_with_audio_captured_the_sound_is_the_wheels() -> None:
    wheel, built = _open("Trekker-GameBoy", "Level1")
    try:
        for emulator in (wheel, built):
            emulator.capture_audio(True)  # then the host tells the built core that the sound is heard
        for _ in range(50):
            wheel.run([0], 4)
            built.run([0], 4)
        heard = wheel.take_audio()
        assert len(heard) > 50 * 4 * 500 and np.array_equal(built.take_audio(), heard)
    finally:
        wheel.close()
        built.close()
