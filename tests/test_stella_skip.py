"""The stella ``retrokit build-core stella`` makes, which skips converting the frames nobody sees, against the wheel's.

Both cores play each of ale-py's 32 stable-retro games from its shipped state
on the same random buttons (new ones every 4 frames, both ports, no console
switch) for 2,000 frames, in runs of 4 frames: the built core told that only
each run's last frame is seen (as an RGB env at frame skip 4 tells it), the
wheel's drawing every frame. After every run the RAM and the screen are
equal, and at the end the whole state. The built core asks on every frame
and is told to draw once a run. With audio captured, both hand over the same
samples. Skipped when the core is not built (``retrokit build-core stella``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from skipplay import check_alike

from retrokit.host.cores import built_core
from retrokit.host.emulator import Emulator
from retrokit.host.systems import get_system
from retrokit.paths import wheel_cores_dir

ale_py = pytest.importorskip("ale_py")
pytestmark = pytest.mark.skipif(built_core("stella") is None, reason="the patched stella is not built "
                                "(retrokit build-core stella)")

FRAMES = 2000
# stable-retro's name -> ale-py's ROM
GAMES = {
    "Adventure": "adventure", "AirRaid": "air_raid", "Alien": "alien", "Asterix": "asterix", "Asteroids": "asteroids",
    "BeamRider": "beam_rider", "Bowling": "bowling", "Boxing": "boxing", "Breakout": "breakout",
    "ChopperCommand": "chopper_command", "CrazyClimber": "crazy_climber", "ElevatorAction": "elevator_action",
    "Enduro": "enduro", "FishingDerby": "fishing_derby", "Freeway": "freeway", "Frostbite": "frostbite",
    "Hero": "hero", "Jamesbond": "jamesbond", "JourneyEscape": "journey_escape", "Kangaroo": "kangaroo",
    "MontezumaRevenge": "montezuma_revenge", "Phoenix": "phoenix", "Pong": "pong", "PrivateEye": "private_eye",
    "Qbert": "qbert", "Robotank": "robotank", "Seaquest": "seaquest", "Solaris": "solaris",
    "StarGunner": "star_gunner", "TimePilot": "time_pilot", "UpNDown": "up_n_down", "Zaxxon": "zaxxon",
}


def _open(game: str) -> tuple[Emulator, Emulator]:
    """The wheel's stella and the built one, each at ``game``'s shipped state."""
    from retrokit.data.statecheck import vet_state
    from retrokit.data.states import read_state
    from retrokit.paths import wheel_dir

    rom = Path(ale_py.__file__).parent / "roms" / f"{GAMES[game]}.bin"
    path = wheel_dir() / "data" / "stable" / f"{game}-Atari2600-v0" / "Start.state"
    state = vet_state(read_state(path), "Atari2600", rom, source=str(path))
    wheel = Emulator("Atari2600", rom, core_path=wheel_cores_dir() / "stella_libretro.so")
    built = Emulator("Atari2600", rom)  # finds the build in the data folder first
    for emulator in (wheel, built):
        emulator.set_state(state)
    built.set_video_frames("last")
    return wheel, built


@pytest.mark.parametrize("game", list(GAMES))
def test_the_built_stella_plays_as_the_wheels_converting_only_the_seen_frames(game: str) -> None:
    switches = get_system("Atari2600").mask(["SELECT", "RESET"])
    buttons = np.random.default_rng(0).integers(0, 1 << 8, size=(FRAMES // 4, 2)) & ~switches
    check_alike(*_open(game), buttons)


def test_with_audio_captured_the_sound_is_the_wheels() -> None:
    wheel, built = _open("Pong")
    try:
        for emulator in (wheel, built):
            emulator.capture_audio(True)  # then the host tells the built core that the sound is heard
        for _ in range(50):
            wheel.run([0, 0], 4)
            built.run([0, 0], 4)
        heard = wheel.take_audio()
        assert len(heard) > 50 * 4 * 500 and np.array_equal(built.take_audio(), heard)  # ~524 samples a frame
    finally:
        wheel.close()
        built.close()
