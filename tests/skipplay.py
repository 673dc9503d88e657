"""Playing a core ``retrokit build-core`` made beside the wheel's, for the tests of each patched core.

The built core is told that only the last frame of each run of 4 is seen (as an RGB env at frame skip 4
tells it); the wheel's draws every frame. Both get the same buttons.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from retrokit.data.games import find_game
from retrokit.data.statecheck import vet_state
from retrokit.data.states import read_state
from retrokit.host.emulator import Emulator
from retrokit.paths import wheel_cores_dir


def open_pair(game_name: str, state: str) -> tuple[Emulator, Emulator]:
    """The wheel's core of ``game_name``'s system and the built one, each at its ``state``, the built one told
    that only the last frame of a run is seen."""
    game = find_game(game_name)
    rom = game.require_rom()
    path = game.state_path(state)
    data = vet_state(read_state(path), game.system.name, rom, source=str(path))
    wheel = Emulator(game.system.name, rom, core_path=wheel_cores_dir() / f"{game.system.core}_libretro.so")
    built = Emulator(game.system.name, rom)  # finds the build in the data folder first
    for emulator in (wheel, built):
        emulator.set_state(data)
    built.set_video_frames("last")
    return wheel, built


def play_alike(wheel: Emulator, built: Emulator, buttons: np.ndarray) -> set[bytes]:
    """Run both cores 4 frames for each row of ``buttons`` (one mask per port); return the screens seen.

    After every run the RAM and the screen are equal; over the whole play the built core asked on every
    frame and was told to draw one in four, and the wheel's never asked.
    """
    asked, drawn = built.av_asked, built.av_drawn
    screens = set()
    for run, pads in enumerate(buttons):
        wheel.run([int(pad) for pad in pads], 4)
        built.run([int(pad) for pad in pads], 4)
        assert np.array_equal(built.ram, wheel.ram), f"RAM after frame {4 * run + 4}"
        screen = built.screen()
        assert np.array_equal(screen, wheel.screen()), f"the screen after frame {4 * run + 4}"
        screens.add(screen.tobytes())
    frames = 4 * len(buttons)
    assert built.av_asked - asked == frames and built.av_drawn - drawn == frames // 4  # asked every frame, drew 1 in 4
    assert wheel.av_asked == 0  # the wheel's never asks
    return screens


def check_alike(wheel: Emulator, built: Emulator, buttons: np.ndarray,
                emulated: Callable[[bytes], bytes] = lambda state: state) -> None:
    """:func:`play_alike`, then the whole states (as ``emulated`` keeps them) equal and the game moved; closes both."""
    try:
        screens = play_alike(wheel, built, buttons)
        assert emulated(built.get_state()) == emulated(wheel.get_state())
        assert len(screens) > 10  # the game moved
    finally:
        wheel.close()
        built.close()
