"""Reloading the game before a state load (``reload_before_state``), and the memory views that must follow it.

stella keeps Breakout's paddle charge in the controller object its console
owns, outside any state, and a console reset leaves it alone: only a fresh
load of the game starts it at the middle again, as stable-retro's reload of the
core does before every load. The reload frees the memory the core showed, so
the views of it that the emulator's :class:`AddressSpace` holds (and every
field reader reads through) are let go before and made again after, and the
native host refuses to reload while any other view is alive.
"""

from __future__ import annotations

import dataclasses
import pickle
from pathlib import Path

import numpy as np
import pytest

from retrokit.errors import CoreError
from retrokit.host.emulator import Emulator, VettedState
from retrokit.host.memory import FieldReader
from retrokit.host.systems import get_system

ale_py = pytest.importorskip("ale_py")

LEFT, RIGHT = get_system("Atari2600").mask(["LEFT"]), get_system("Atari2600").mask(["RIGHT"])


@pytest.fixture(scope="module")
def breakout_rom() -> Path:
    return Path(ale_py.__file__).parent / "roms" / "breakout.bin"


@pytest.fixture(scope="module")
def breakout_state(breakout_rom: Path) -> VettedState:
    """stable-retro's shipped Breakout start, checked for ale-py's ROM (stable-retro's, by its SHA-1)."""
    from retrokit.data.statecheck import vet_state
    from retrokit.data.states import read_state
    from retrokit.paths import wheel_dir

    path = wheel_dir() / "data" / "stable" / "Breakout-Atari2600-v0" / "Start.state"
    return vet_state(read_state(path), "Atari2600", breakout_rom, source=str(path))


def _play(emulator: Emulator, state: VettedState) -> list[np.ndarray]:
    """Load ``state``, then hold LEFT and RIGHT in turn (the paddle's charge moves); the screens seen."""
    emulator.set_state(state)
    screens = []
    for mask in [LEFT] * 20 + [RIGHT] * 5 + [0] * 5:
        emulator.run([mask, 0], 4)
        screens.append(emulator.screen())
    return screens


def _same(a: list[np.ndarray], b: list[np.ndarray]) -> bool:
    return len(a) == len(b) and all(np.array_equal(x, y) for x, y in zip(a, b))


def test_atari_reloads_its_game_before_a_state() -> None:
    assert get_system("Atari2600").reload_before_state
    assert not get_system("Genesis").reload_before_state  # Genesis Plus GX's states hold the whole console


def test_every_load_of_a_state_plays_alike_as_on_a_fresh_core(breakout_rom: Path, breakout_state: VettedState) -> None:
    with Emulator("Atari2600", breakout_rom) as emulator:
        first, second = _play(emulator, breakout_state), _play(emulator, breakout_state)
    with Emulator("Atari2600", breakout_rom) as fresh:
        fresh_play = _play(fresh, breakout_state)
    assert _same(first, second) and _same(first, fresh_play)
    assert len({s.tobytes() for s in first}) > 5  # the paddle moved: the game took the input


def test_without_the_reload_the_paddle_charge_leaks_into_the_next_load(
    breakout_rom: Path, breakout_state: VettedState
) -> None:
    # The descriptor fact is what makes loads alike: with it off, the console reset leaves the charge as it was.
    system = dataclasses.replace(get_system("Atari2600"), reload_before_state=False)
    with Emulator(system, breakout_rom) as emulator:
        assert not _same(_play(emulator, breakout_state), _play(emulator, breakout_state))


def _play_from_power_on(emulator: Emulator) -> list[np.ndarray]:
    """Hard-reset, start a game, move the paddle left then right: the screens seen."""
    emulator.reset()
    start, fire = emulator.system.mask(["RESET"]), emulator.system.mask(["BUTTON"])
    screens = []
    for mask in [start] * 3 + [0] * 10 + [LEFT] * 20 + [fire | RIGHT] * 5:
        emulator.run([mask, 0], 4)
        screens.append(emulator.screen())
    return screens


@pytest.mark.parametrize("reload", [True, False], ids=["reloaded-alike", "reset-only-unalike"])
def test_every_hard_reset_plays_alike_only_with_the_reload(breakout_rom: Path, reload: bool) -> None:
    system = dataclasses.replace(get_system("Atari2600"), reload_before_state=reload)
    with Emulator(system, breakout_rom) as emulator:
        assert _same(_play_from_power_on(emulator), _play_from_power_on(emulator)) == reload


def test_the_address_space_and_its_readers_follow_the_reload(breakout_rom: Path, breakout_state: VettedState) -> None:
    from retrokit.host.fields import FieldSpec

    with Emulator("Atari2600", breakout_rom) as emulator:
        space, before = emulator.space, emulator.space.buffers[0]
        reader = FieldReader([FieldSpec("first", 0x80, "|u1"), FieldSpec("last", 0xFF, "|u1")], space)
        emulator.run([LEFT, 0], 30)
        emulator.set_state(breakout_state)
        # The views made before the reload are released (they would show freed memory): reading one raises.
        with pytest.raises(ValueError, match="released"):
            before[0]
        assert emulator.space is space and space.buffers[0] is not before
        # The reader made before reads the memory the core has now, and writes reach it.
        ram = emulator.ram.copy()
        assert reader.read() == {"first": int(ram[0]), "last": int(ram[127])}
        emulator.poke(0x80, (int(ram[0]) + 1) & 0xFF)
        assert emulator.ram[0] == (int(ram[0]) + 1) & 0xFF


def test_a_view_alive_across_a_reload_is_refused_in_one_line_and_nothing_changes(
    breakout_rom: Path, breakout_state: VettedState
) -> None:
    with Emulator("Atari2600", breakout_rom) as emulator:
        emulator.run([0, 0], 10)
        frame = emulator.frame
        ram = emulator.ram  # the caller's array: it would point at freed memory after the reload
        with pytest.raises(CoreError, match="no view of this emulator's memory to be alive") as error:
            emulator.set_state(breakout_state)
        assert "\n" not in str(error.value) and emulator.frame == frame
        assert emulator.peek(0x80) == ram[0]  # the space shows the memory again
        del ram
        kept = np.frombuffer(emulator.space.buffers[0], dtype=np.uint8)  # an array over the space's own view
        with pytest.raises(CoreError, match="no view of this emulator's memory to be alive"):
            emulator.set_state(breakout_state)
        assert emulator.peek(0x80) == kept[0]
        del kept
        held = pickle.PickleBuffer(emulator.space.buffers[0])  # a buffer taken from the space's view itself
        with pytest.raises(CoreError, match="found one onto 0x80-0xff"):
            emulator.set_state(breakout_state)
        assert emulator.peek(0x80) == emulator.ram[0]
        del held
        emulator.set_state(breakout_state)  # with every view gone, the load goes through
        assert emulator.peek(0x80) == emulator.ram[0]


def test_a_game_loaded_without_a_copy_cannot_be_reloaded(airstriker: Emulator) -> None:
    with pytest.raises(CoreError, match="without keeping a copy"):
        airstriker.handle.reload()
    airstriker.run(0, 1)  # still loaded and running


def test_a_genesis_game_reloads_too_when_its_descriptor_says_so(
    airstriker_rom: Path, airstriker_state: bytes, airstriker_fields: dict[str, dict]
) -> None:
    from retrokit.host.fields import FieldSpec

    system = dataclasses.replace(get_system("Genesis"), reload_before_state=True)
    specs = [FieldSpec(name, f["address"], f["type"]) for name, f in airstriker_fields.items()]
    with Emulator(system, airstriker_rom) as emulator:
        reader = FieldReader(specs, emulator.space)
        emulator.set_state(airstriker_state)
        emulator.run(0, 60)
        played = (emulator.screen(), reader.read())
        emulator.set_state(airstriker_state)
        emulator.run(0, 60)
        assert np.array_equal(played[0], emulator.screen()) and played[1] == reader.read()


def test_an_env_plays_each_episode_alike(breakout_rom: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import shutil

    import retrokit

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path))
    (tmp_path / "roms" / "Breakout-Atari2600").mkdir(parents=True)
    shutil.copy(breakout_rom, tmp_path / "roms" / "Breakout-Atari2600" / "rom.a26")
    with retrokit.make("Breakout-Atari2600", action_type="all", noop_max=1) as env:
        actions = np.zeros((40, len(env.buttons)), dtype=np.int8)
        actions[:30, env.buttons.index("LEFT")] = 1
        actions[::3, env.buttons.index("BUTTON")] = 1  # serve, then keep pressing
        episodes = []
        for _ in range(2):
            obs, info = env.reset(seed=0)
            seen = [(obs, info)] + [env.step(a)[::4] for a in actions]
            episodes.append(seen)
    first, second = episodes
    assert all(np.array_equal(a[0], b[0]) and a[1] == b[1] for a, b in zip(first, second, strict=True))
