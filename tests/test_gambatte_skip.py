"""The gambatte ``retrokit build-core gambatte`` makes, which skips the sound nobody hears, against the wheel's.

Both cores play Trekker (our Game Boy cartridge, as a Game Boy and as a Game
Boy Color game) from each level's state, on the same random buttons (new ones
every 4 frames) for 2,000 frames in runs of 4: the built core told that only
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
from skipplay import check_alike, open_pair

from retrokit.host.cores import built_core

pytestmark = pytest.mark.skipif(built_core("gambatte") is None, reason="the patched gambatte is not built "
                                "(retrokit build-core gambatte)")

FRAMES = 2000


def _emulated(state: bytes) -> bytes:
    """A gambatte state without its ``dmgpal`` field (the colours a Game Boy Color gives a Game Boy game).

    Saved from memory the core never fills on a Game Boy (it held a heap address), so two of the wheel's own
    cores, opened from the same state and played alike, disagree there and nowhere else.
    """
    at = state.index(b"dmgpal\0") + len(b"dmgpal\0")
    size = int.from_bytes(state[at : at + 3], "big")
    return state[: at + 3] + bytes(size) + state[at + 3 + size :]


@pytest.mark.parametrize("game", ["Trekker-GameBoy", "Trekker-GbColor"])
@pytest.mark.parametrize("state", ["Level1", "Level2", "Level3"])
def test_the_built_gambatte_plays_as_the_wheels_making_no_unheard_sound(game: str, state: str) -> None:
    buttons = np.random.default_rng(len(state) + len(game)).integers(0, 1 << 8, size=(FRAMES // 4, 1))
    check_alike(*open_pair(game, state), buttons, _emulated)


def test_with_audio_captured_the_sound_is_the_wheels() -> None:
    wheel, built = open_pair("Trekker-GameBoy", "Level1")
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
