"""retrokit reads what stable-retro reads, on the same core, frames and inputs.

This is the one place retrokit's tests import stable-retro's Python: as the
reference to compare against.
"""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest

from retrokit.data.statecheck import vet_state
from retrokit.host.emulator import Emulator
from retrokit.host.fields import FieldSpec
from retrokit.host.memory import FieldReader
from retrokit.paths import wheel_dir

stable_retro = pytest.importorskip("stable_retro")

STEPS = 1500


def test_airstriker_fields_and_frames_match_stable_retro(airstriker_fields: dict[str, dict]) -> None:
    # ALL: every button reaches the core as pressed, with no combination filter.
    env = stable_retro.make("Airstriker-Genesis-v0", render_mode=None, use_restricted_actions=stable_retro.Actions.ALL)
    try:
        env.reset(seed=0)
        reference = env.unwrapped
        ours = Emulator("Genesis", reference.romfile if hasattr(reference, "romfile") else _rom_path())
        ours.set_state(vet_state(reference.em.get_state(), "Genesis", ours.rom))  # stable-retro's: probed once
        reader = FieldReader(
            [FieldSpec(name, spec["address"], spec["type"]) for name, spec in airstriker_fields.items()], ours.space
        )
        rng = np.random.default_rng(0)
        buttons = list(reference.buttons)
        seen_scores = set()
        for step in range(STEPS):
            # Tap fire and wander, so the ship shoots, scores and dies on the way.
            if step % 8 == 0:
                move = [["UP"], ["DOWN"], ["LEFT"], ["RIGHT"], [], ["A", "C"]][rng.integers(0, 6)]
            names = (["B"] if step % 8 < 4 else []) + move
            pressed = np.array([b in names for b in buttons], dtype=np.int8)
            _, _, _, _, info = env.step(pressed)
            ours.run([ours.system.mask(names), 0], 1)
            got = reader.read()
            assert got == {k: info[k] for k in got}, f"step {step}"
            if step % 50 == 0:
                assert (ours.screen() == reference.em.get_screen()).all(), f"screen at step {step}"
            seen_scores.add(got["score"])
        # The comparison covered a game in motion, not a frozen screen.
        assert len(seen_scores) > 3
        ours.close()
    finally:
        env.close()


def _rom_path() -> Path:
    return wheel_dir() / "data" / "stable" / "Airstriker-Genesis-v0" / "rom.md"


SONIC_GAMES = ["SonicTheHedgehog-Genesis-v0", "SonicTheHedgehog2-Genesis-v0", "SonicAndKnuckles3-Genesis-v0"]


def sonic_states() -> list[Path]:
    root = wheel_dir()
    if root is None:
        return []
    return sorted(p for game in SONIC_GAMES for p in (root / "data" / "stable" / game).glob("*.state"))


def test_the_wheel_ships_58_sonic_states() -> None:
    assert len(sonic_states()) == 58


@pytest.fixture(scope="module")
def genesis(airstriker_rom: Path):
    emu = Emulator("Genesis", airstriker_rom)
    yield emu
    emu.close()


@pytest.mark.parametrize("state", sonic_states(), ids=lambda p: f"{p.parent.name.split('-')[0]}/{p.stem}")
def test_sonic_state_is_accepted_by_the_core_unchanged(genesis: Emulator, state: Path) -> None:
    # Without the Sonic ROM, the most we can show is that Genesis Plus GX takes
    # the state as it is: the right size, a valid header, restored without error.
    data = gzip.decompress(state.read_bytes())
    genesis.set_state(vet_state(data, "Genesis", genesis.rom, shipped=state))  # the wheel ships it: no probe
    assert genesis.get_state()[:16] == data[:16]


@pytest.mark.parametrize("reset_frame", [True, False], ids=["reset_frame", "no_reset_frame"])
def test_reset_frame_replays_stable_retro_step_for_step(reset_frame: bool) -> None:
    import retrokit

    reference = stable_retro.make("Airstriker-Genesis-v0", render_mode=None, use_restricted_actions=stable_retro.Actions.ALL)
    ours = retrokit.make("Airstriker-Genesis", action_type="all", reset_frame=reset_frame, skip_video=False)
    try:
        theirs_obs, _ = reference.reset(seed=0)
        obs, _ = ours.reset(seed=0)
        same = [bool((obs == theirs_obs).all())]
        rng = np.random.default_rng(1)
        for step in range(300):
            action = (rng.random(12) < 0.3).astype(np.int8)
            theirs = reference.step(action)
            got = ours.step(action)
            same.append(bool((got[0] == theirs[0]).all()))
            if reset_frame:
                assert got[1:3] == theirs[1:3] and got[4] == {k: theirs[4][k] for k in got[4]}, f"step {step}"
        # With stable-retro's reset frame every observation is the same; without it, each comes a frame earlier.
        assert all(same) if reset_frame else not all(same)
    finally:
        ours.close()
        reference.close()
