"""Playing a core ``retrokit build-core`` made beside the wheel's, for the tests of each patched core.

The built core is told that only the last frame of each run of 4 is seen (as an RGB env at frame skip 4
tells it); the wheel's draws every frame. Both get the same buttons.
"""

from __future__ import annotations

import numpy as np

from retrokit.host.emulator import Emulator


def play_alike(wheel: Emulator, built: Emulator, buttons: np.ndarray) -> set[bytes]:
    """Run both cores 4 frames for each row of ``buttons`` (one mask per port); return the screens seen.

    After every run the RAM and the screen are equal; over the whole play the built core asked on every
    frame and drew at most one in four, and the wheel's never asked.
    """
    asked = built.av_asked
    screens = set()
    for run, pads in enumerate(buttons):
        wheel.run([int(pad) for pad in pads], 4)
        built.run([int(pad) for pad in pads], 4)
        assert np.array_equal(built.ram, wheel.ram), f"RAM after frame {4 * run + 4}"
        screen = built.screen()
        assert np.array_equal(screen, wheel.screen()), f"the screen after frame {4 * run + 4}"
        screens.add(screen.tobytes())
    frames = 4 * len(buttons)
    assert built.av_asked - asked == frames and built.av_drawn <= asked + frames // 4  # asked every frame, drew 1 in 4
    assert wheel.av_asked == 0  # the wheel's never asks
    return screens
