"""The snes9x, fceumm and mednafen_pce_fast ``retrokit build-core`` makes, which skip unseen frames, against the wheel's.

Each plays our cartridge of its system from a state of each of its levels (one for 2 players where the game
has them) on both cores, on the same random buttons of both pads (new ones every 4 frames) for 2,000 frames
in runs of 4: the built core told that only each run's last frame is seen (as an RGB env at frame skip 4
tells it), the wheel's drawing every frame. After every run the RAM and the screen are equal, and at the end
the whole state (tests/skipplay.py). Each core's cases skip when it is not built (``retrokit build-core
<core>``). gambatte's own test is test_gambatte_skip.py (its states hold a field no two cores agree on).
"""

from __future__ import annotations

import numpy as np
import pytest
from skipplay import check_alike, open_pair

from retrokit.host.cores import built_core

FRAMES = 2000
# core -> (our cartridge of its system, its states)
PLAYS = {
    "snes9x": ("Skipper-Snes", ["Level1", "Level2.2P", "Level3"]),
    "fceumm": ("Hopper-Nes", ["Level1-1", "Level2-1.2P", "Level3-1"]),
    "mednafen_pce_fast": ("Skipper-PCEngine", ["Level1", "Level2", "Level3"]),
}


def _cases() -> list:
    return [
        pytest.param(core, game, state, id=f"{core}-{state}", marks=pytest.mark.skipif(
            built_core(core) is None, reason=f"the patched {core} is not built (retrokit build-core {core})"))
        for core, (game, states) in PLAYS.items()
        for state in states
    ]  # fmt: skip


@pytest.mark.parametrize(("core", "game", "state"), _cases())
def test_the_built_core_plays_as_the_wheels_drawing_only_the_seen_frames(core: str, game: str, state: str) -> None:
    buttons = np.random.default_rng(len(state)).integers(0, 1 << 12, size=(FRAMES // 4, 2))
    check_alike(*open_pair(game, state), buttons)
