"""Reloading the game before a state load (``reload_before_state``), and the memory views that must follow it.

stella keeps Breakout's paddle charge in the controller object its console
owns, outside any state, and a console reset leaves it alone: only a fresh
load of the game starts it at the middle again, as stable-retro's reload of the
core does before every load. The reload frees the memory the core showed, so
the views of it that the emulator's :class:`AddressSpace` holds (and every
field reader reads through) are let go before and made again after, and the
native host refuses to reload while any other view is alive.

A game on joysticks keeps nothing outside its states (``reload_only_for``):
its state loads and hard resets load no game, and play as a fresh console's.
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


def _shipped(game: str, rom: Path) -> VettedState:
    """stable-retro's shipped start of ``game``, checked for ale-py's ROM (stable-retro's, by its SHA-1)."""
    from retrokit.data.statecheck import vet_state
    from retrokit.data.states import read_state
    from retrokit.paths import wheel_dir

    path = wheel_dir() / "data" / "stable" / f"{game}-Atari2600-v0" / "Start.state"
    return vet_state(read_state(path), "Atari2600", rom, source=str(path))


@pytest.fixture(scope="module")
def breakout_state(breakout_rom: Path) -> VettedState:
    return _shipped("Breakout", breakout_rom)


def _play(emulator: Emulator, state: VettedState, turn: tuple[int, int] = (LEFT, RIGHT)) -> list[np.ndarray]:
    """Load ``state``, then hold one way and the other in turn (the paddle's charge moves); the screens seen."""
    emulator.set_state(state)
    screens = []
    for mask in [turn[0]] * 20 + [turn[1]] * 5 + [0] * 5:
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


@pytest.mark.parametrize("game,rom,turn", [("Breakout", "breakout", "LEFT RIGHT"), ("Pong", "pong", "UP DOWN")])
def test_without_the_reload_the_paddle_charge_leaks_into_the_next_load(game: str, rom: str, turn: str) -> None:
    # The descriptor fact is what makes loads alike: with it off, the console reset leaves the charge as it was.
    # Pong is Video Olympics to stella, on paddles too, their axes swapped (UP and DOWN turn the player's).
    path = Path(ale_py.__file__).parent / "roms" / f"{rom}.bin"
    state = _shipped(game, path)
    masks = tuple(get_system("Atari2600").mask([b]) for b in turn.split())
    with Emulator("Atari2600", path) as emulator:
        assert emulator.reloads_states
        assert _same(_play(emulator, state, masks), _play(emulator, state, masks))
    system = dataclasses.replace(get_system("Atari2600"), reload_before_state=False)
    with Emulator(system, path) as emulator:
        assert not _same(_play(emulator, state, masks), _play(emulator, state, masks))


def _random_play(emulator: Emulator, frames: int, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """``frames`` frames of random joystick buttons (no console switch): the screen and RAM after each 4."""
    buttons = emulator.system.mask(["BUTTON", "UP", "DOWN", "LEFT", "RIGHT"])
    masks = np.random.default_rng(seed).integers(0, 256, size=frames) & buttons
    seen = []
    for i, mask in enumerate(masks):
        emulator.run([int(mask), int(masks[-1 - i])], 1)
        if i % 4 == 3:
            seen.append((emulator.screen(), emulator.ram.copy()))
    return seen


def _alike(a: list[tuple[np.ndarray, np.ndarray]], b: list[tuple[np.ndarray, np.ndarray]]) -> bool:
    return len(a) == len(b) and all(np.array_equal(x[0], y[0]) and np.array_equal(x[1], y[1]) for x, y in zip(a, b))


def test_a_joystick_games_loads_and_hard_resets_load_no_game_and_play_as_a_fresh_consoles() -> None:
    # Freeway: joysticks, a 2K cartridge. Each load and hard reset follows 400 frames of other random play.
    rom = Path(ale_py.__file__).parent / "roms" / "freeway.bin"
    state = _shipped("Freeway", rom)
    with Emulator("Atari2600", rom) as fresh:
        assert not fresh.reloads_states
        fresh.set_state(state)
        from_state = _random_play(fresh, 400, 1)
    with Emulator("Atari2600", rom) as fresh:
        fresh.reset()  # the first hard reset reloads, as every one did
        from_power_on = _random_play(fresh, 400, 1)
    with Emulator("Atari2600", rom) as emulator:
        emulator.reset()
        for _ in range(2):
            _random_play(emulator, 400, 2)
            view = emulator.space.buffers[0]
            emulator.set_state(state)
            assert emulator.space.buffers[0] is view  # no reload: the memory the core showed is the same
            assert _alike(_random_play(emulator, 400, 1), from_state)
            _random_play(emulator, 400, 3)
            emulator.reset()
            assert emulator.space.buffers[0] is view
            assert _alike(_random_play(emulator, 400, 1), from_power_on)
    assert len({screen.tobytes() for screen, _ in from_state}) > 5  # the game moved


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


@pytest.mark.parametrize(
    "state,expected",
    [
        pytest.param(b"\x0d\x00\x00\x0003090100state\x0b\x00\x00\x00CartridgeF8rest", "CartridgeF8", id="stella"),
        pytest.param(b"", "", id="empty"),
        pytest.param(b"\x0d\x00\x00\x0003090100state\xff\xff\xff\xffCartridge", "", id="a-length-past-the-end"),
        pytest.param(b"\x0d\x00\x00\x0003090100state\x05\x00\x00\x00Other", "", id="not-a-cartridge"),
        pytest.param(b"GENPLUS-GX" + bytes(100), "", id="a-genesis-state"),
        pytest.param(b"\x0d\x00\x00\x0003090100state\x0b\x00\x00\x00Cartridge\xff\xfe", "", id="not-ascii"),
    ],
)
def test_the_cartridge_class_is_read_from_a_stella_state_and_nothing_else(state: bytes, expected: str) -> None:
    from retrokit.host.statelayout import cartridge_class

    assert cartridge_class(state) == expected


def test_the_reload_rule_names_roms_by_md5_and_cartridge() -> None:
    atari = get_system("Atari2600")
    breakout_md5 = "f34f08e5eb96e500e851a80be3277a56"  # stella's properties: PADDLES
    assert atari.reloads_states(breakout_md5, "Cartridge2K") and atari.reloads_states("0" * 32, "CartridgeF8SC")
    assert not atari.reloads_states("0" * 32, "CartridgeF8")
    every = dataclasses.replace(atari, reload_md5=frozenset(), reload_cartridges=frozenset())
    assert every.reloads_states("0" * 32, "")  # no list: every ROM reloads, as before
    assert not get_system("Genesis").reloads_states(breakout_md5, "CartridgeF8SC")
