"""Atari 2600, proven against stable-retro with ale-py's ROMs: 32 games from their shipped states.

ale-py (a test dependency) ships Atari 2600 ROMs; 32 of them have the SHA-1
of a stable-retro Atari2600 integration. They are imported once for the
module into a temporary data folder, and each game plays from its shipped
default state in retrokit and in stable-retro, on the same stella core, with
the same random inputs: observation, reward, done and every info field match
frame for frame, and movies recorded by one play in the other.

stable-retro's reset runs one frame with no buttons; retrokit's
``noop_max=1`` runs the same frame. stable-retro reloads the stella core
before every state load; retrokit resets the console before each load
(``reset_before_state`` in systems.yaml), and reloads the game first only
for the ROMs whose console keeps state outside its states
(``reload_only_for``): here Pong and Breakout (paddles) and Elevator Action
(an F8SC cartridge, whose write port reads the console's random generator).
Each game's env is reset a second time and plays the same buttons again:
screens, steps and the whole RAM equal the first play's, a fresh console's.
"""

from __future__ import annotations

import contextlib
import itertools
import os
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import retrokit
from retrokit.cli import main
from retrokit.movie import play, read_bk2

stable_retro = pytest.importorskip("stable_retro")
ale_py = pytest.importorskip("ale_py")

STEPS = 400  # 6.7 s of game from each shipped state, on new random buttons every frame
MOVIE_STEPS = 100  # of each play, replayed from the other side's movie
SWITCHES = ("SELECT", "RESET")  # console switches: pressed at random they restart or change the game
GAMES = [
    "Adventure", "AirRaid", "Alien", "Asterix", "Asteroids", "BeamRider", "Bowling", "Boxing", "Breakout",
    "ChopperCommand", "CrazyClimber", "ElevatorAction", "Enduro", "FishingDerby", "Freeway", "Frostbite", "Hero",
    "Jamesbond", "JourneyEscape", "Kangaroo", "MontezumaRevenge", "Phoenix", "Pong", "PrivateEye", "Qbert",
    "Robotank", "Seaquest", "Solaris", "StarGunner", "TimePilot", "UpNDown", "Zaxxon",
]
# Games that may not match stable-retro, with why (a strict xfail): none. Breakout's paddles keep their charge
# outside the state; both reload the game before each load (reload_before_state), so the paddles start fresh.
DIVERGES: dict[str, str] = {}
# The games whose state loads reload the game (systems.yaml's reload_only_for): stella's properties give Pong (Video
# Olympics) and Breakout paddles; Elevator Action's cartridge is an F8SC. The others' resets load no game.
RELOADED = {"Breakout", "ElevatorAction", "Pong"}


@contextlib.contextmanager
def _data_folder(path: Path) -> Iterator[None]:
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("RETROKIT_DATA", str(path))
        yield


@pytest.fixture(scope="module")
def imported(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """A data folder with ale-py's ROMs imported (one import for the module), set as RETROKIT_DATA."""
    data = tmp_path_factory.mktemp("ale-data")
    with _data_folder(data):
        assert main(["import", "--from", "ale-py"]) == 0
        yield data


@pytest.fixture(scope="module")
def integrations(imported: Path, tmp_path_factory: pytest.TempPathFactory) -> Iterator[object]:
    """stable-retro's integrations, with the imported ROMs in a custom folder beside them."""
    from stable_retro.data import Integrations

    custom = tmp_path_factory.mktemp("stable-retro-roms")
    for game in GAMES:
        folder = custom / f"{game}-Atari2600-v0"
        folder.mkdir()
        (folder / "rom.a26").symlink_to(imported / "roms" / f"{game}-Atari2600" / "rom.a26")
    Integrations.add_custom_path(str(custom))
    yield Integrations.CUSTOM
    Integrations.clear_custom_paths()


def test_ale_py_roms_import_as_the_32_stable_retro_games(imported: Path) -> None:
    assert sorted(p.name for p in (imported / "roms").iterdir()) == sorted(f"{g}-Atari2600" for g in GAMES)


def _inputs(buttons: list[str | None], steps: int) -> np.ndarray:
    rng = np.random.default_rng(0)
    actions = rng.integers(0, 2, size=(steps, len(buttons))).astype(np.int8)
    actions[:, [i for i, b in enumerate(buttons) if b is None or b in SWITCHES]] = 0  # unused ids: no .bk2 letter
    return actions


def _play(env, actions: np.ndarray, ram: list[np.ndarray] | None = None) -> tuple[list[np.ndarray], list[tuple]]:
    obs, _ = env.reset(seed=0)
    screens, steps = [obs], []
    for action in actions:
        obs, reward, terminated, truncated, info = env.step(action)
        screens.append(obs)
        steps.append((reward, terminated, truncated, info))
        if ram is not None:
            ram.append(env.unwrapped.emulator.ram.copy())
        if terminated or truncated:
            break
    return screens, steps


def _first_difference(ours: list, theirs: list) -> int | None:
    for i, (a, b) in enumerate(zip(ours, theirs, strict=False)):
        if not (np.array_equal(a, b) if isinstance(a, np.ndarray) else a == b):
            return i
    return None if len(ours) == len(theirs) else min(len(ours), len(theirs))


def _marks(game: str) -> list:
    return [pytest.mark.xfail(reason=DIVERGES[game], strict=True)] if game in DIVERGES else []


@pytest.mark.parametrize("game", [pytest.param(g, marks=_marks(g)) for g in GAMES])
def test_game_matches_stable_retro_frame_for_frame_and_movies_pass_both_ways(
    game: str, integrations, tmp_path: Path
) -> None:
    # One play on each side, each recording its movie: each movie's first MOVIE_STEPS frames are then replayed on
    # the other side against the screens this play showed (no second play of the same inputs to record them).
    theirs = stable_retro.make(f"{game}-Atari2600-v0", inttype=integrations, render_mode=None, record=str(tmp_path),
                               use_restricted_actions=stable_retro.Actions.ALL)
    try:
        actions = _inputs(theirs.unwrapped.buttons, STEPS)
        their_screens, their_steps = _play(theirs, actions)
        theirs.unwrapped.stop_record()
    finally:
        theirs.close()
    ours = tmp_path / "ours"
    with retrokit.make(f"{game}-Atari2600", action_type="all", noop_max=1, record=ours) as env:
        assert env.buttons == theirs.unwrapped.buttons
        assert env.unwrapped.emulator.reloads_states == (game in RELOADED)
        our_ram: list[np.ndarray] = []
        our_screens, our_steps = _play(env, actions, our_ram)
        # The same buttons from a second reset (a state load into the console the first play left): all alike.
        again_ram: list[np.ndarray] = []
        again_screens, again_steps = _play(env, actions, again_ram)
    assert _first_difference(our_steps, their_steps) is None, "reward, done or info"
    assert _first_difference(our_screens, their_screens) is None, "observation"
    assert _first_difference(again_ram, our_ram) is None, "RAM after the second reset"
    assert _first_difference(again_screens, our_screens) is None, "observation after the second reset"
    assert _first_difference(again_steps, our_steps) is None, "reward, done or info after the second reset"
    # It played from its shipped state: the game moved (a frozen or blank screen would match too).
    assert len({s.tobytes() for s in our_screens}) > 10

    # stable-retro recorded; retrokit plays its movie to the screens stable-retro showed.
    shown = MOVIE_STEPS + 1  # the reset's frame, then a frame a step
    (their_movie,) = tmp_path.glob("*.bk2")
    with contextlib.closing(play(their_movie)) as frames:
        replayed = list(itertools.islice(frames, shown))
    assert _first_difference(replayed, their_screens[:shown]) is None, "stable-retro's movie in retrokit"

    # retrokit recorded; stable-retro plays its movie to the screens retrokit showed.
    our_movie = min(ours.glob("*.bk2"))  # the first episode's (the second reset began another)
    assert len(read_bk2(our_movie).frames) == len(our_screens)
    movie = stable_retro.Movie(str(our_movie))
    emulator = stable_retro.RetroEmulator(str(integrations_rom(game)))
    try:
        emulator.set_state(movie.get_state())
        replayed = []
        while len(replayed) < shown and movie.step():
            keys = [movie.get_key(i, 0) for i in range(len(theirs.unwrapped.buttons))]
            emulator.set_button_mask(np.array(keys, dtype=np.uint8), 0)
            emulator.step()
            replayed.append(emulator.get_screen().copy())
    finally:
        del emulator
    assert _first_difference(replayed, our_screens[:shown]) is None, "retrokit's movie in stable-retro"


def integrations_rom(game: str) -> Path:
    return Path(os.environ["RETROKIT_DATA"]) / "roms" / f"{game}-Atari2600" / "rom.a26"


# --- states: taken as stella takes them, refused for a reason that holds --------------------------------------


def _shipped_state(game: str) -> Path:
    from retrokit.paths import wheel_dir

    return wheel_dir() / "data" / "stable" / f"{game}-Atari2600-v0" / "Start.state"


def test_stable_retros_512_byte_states_load_though_the_core_writes_fewer(imported: Path) -> None:
    from retrokit.data.states import read_state

    state = read_state(_shipped_state("Pong"))
    with retrokit.make("Pong-Atari2600") as env:
        assert len(state) == 512 > len(env.unwrapped.emulator.get_state())
        env.reset(seed=0)
        assert env.step(env.action_space.sample() * 0)[4]["p1_pos"] > 0  # the shipped state's game, not the attract screen


def _vet(data: bytes, game: str = "Pong"):
    from retrokit.data.statecheck import vet_state

    return vet_state(data, "Atari2600", integrations_rom(game), source="the hostile state")


@pytest.mark.parametrize(
    "kind,expected",
    [
        pytest.param("truncated", "core refused the state", id="truncated"),
        pytest.param("another-system", "core can run; found one that it cannot", id="a-genesis-state"),
        pytest.param("another-game", "found Airstriker-Genesis's state", id="the-wheels-airstriker-state"),
        pytest.param("empty", "expected a serialized core state", id="empty"),
        pytest.param("huge", "at most", id="huge-past-the-largest-state"),
    ],
)
def test_a_hostile_state_ends_in_one_clear_error(imported: Path, airstriker_state: bytes, kind: str, expected: str) -> None:
    from retrokit.data.states import MAX_STATE_SIZE, read_state
    from retrokit.errors import StateError

    pong = read_state(_shipped_state("Pong"))
    data = {"truncated": pong[:100], "another-game": bytes(airstriker_state), "empty": b"",
            # one byte changed: no record knows it, so the core itself must refuse it
            "another-system": bytes(airstriker_state[:-1]) + bytes([airstriker_state[-1] ^ 1]),
            "huge": pong + bytes(MAX_STATE_SIZE)}[kind]
    with (
        pytest.raises(StateError, match=expected) as error,
        retrokit.make("Pong-Atari2600", state=_write(imported, data)) as env,
    ):
        env.reset(seed=0)
    assert "\n" not in str(error.value)


def _write(folder: Path, data: bytes) -> Path:
    from retrokit.data.states import compress_state

    path = folder / "hostile.state"
    path.write_bytes(compress_state(data))
    return path


def test_a_state_whose_bank_is_past_the_cartridge_is_refused_before_any_probe(imported: Path) -> None:
    import struct

    from retrokit.data.states import read_state
    from retrokit.errors import StateError

    state = bytearray(read_state(_shipped_state("Hero")))  # an F8 cartridge: 2 banks of 4 KiB
    marker = struct.pack("<I", 11) + b"CartridgeF8"
    at = state.index(marker, state.index(marker) + 1) + len(marker)  # the cartridge's part, after the header
    state[at : at + 2] = struct.pack("<H", 15)  # the core would map myImage + 60 KiB: another object's memory
    with pytest.raises(StateError, match="CartridgeF8 cartridge is in bank 15, of the 2"):
        _vet(bytes(state), "Hero")


# --- a new Atari game from a bare ROM: the system told by its size ------------------------------------------


def test_new_tells_an_atari_rom_by_its_size_without_system(imported: Path, capsys) -> None:
    galaxian = Path(ale_py.__file__).parent / "roms" / "galaxian.bin"  # a ROM stable-retro does not integrate
    assert main(["new", str(galaxian), "--name", "Galaxian-Atari2600"]) == 0
    assert "Made Galaxian-Atari2600 (Atari2600, told by its size" in capsys.readouterr().out
    with retrokit.make("Galaxian-Atari2600", state=retrokit.State.NONE) as env:
        env.reset(seed=0)
        assert env.step(env.action_space.sample() * 0)[0].shape[1] == 160


def test_import_lists_unmatched_bins_as_atari_and_leaves_out_files_that_are_no_roms(imported: Path, capsys) -> None:
    assert main(["import", "--from", "ale-py", "-v"]) == 0
    out = capsys.readouterr().out
    assert "__init__.py" not in out and "Left out" in out and ".py" in out
    unmatched = out.split("Matched no known game")[1].split("Left out")[0].splitlines()[1:]
    assert len(unmatched) > 40 and all(".bin  SHA-1 " in line and line.endswith("  Atari2600") for line in unmatched)


@pytest.mark.parametrize(
    "size,name,expected",
    [
        pytest.param(1, "One-Atari2600", "Expected a ROM of 2048 to 32768 bytes for Atari2600; found 1 bytes", id="1-byte-named"),
        pytest.param(1, "One-Mystery", "whose header, size or file extension tells its system", id="1-byte"),
        pytest.param(100 * 2**20, "Big-Atari2600", "Expected a ROM of at most 32 MiB", id="100-MB"),
    ],
)
def test_new_refuses_a_bin_no_cartridge_is_in_one_line(tmp_path: Path, size: int, name: str, expected: str) -> None:
    from retrokit.data.newgame import new_game
    from retrokit.errors import RomError

    rom = tmp_path / "x.bin"
    with open(rom, "wb") as f:
        f.truncate(size)  # sparse: 100 MB on disk costs nothing, and must not be read
    with _data_folder(tmp_path / "data"), pytest.raises(RomError, match=expected) as error:
        new_game(rom, name)
    assert "\n" not in str(error.value)


# --- Frogger: the frog moves, once the game is started and its intro is over ------------------------------


def _frog_moves(emulator, state, wait: int) -> bool:
    """Whether tapping UP ``wait`` frames after ``state`` changes the game (RAM) from waiting without input."""
    up = emulator.system.mask(["UP"])
    emulator.set_state(state)
    emulator.run([0, 0], wait)
    for _ in range(4):  # four hops: held 4 frames, released 4 (the game moves one hop per press)
        emulator.run([up, 0], 4)
        emulator.run([0, 0], 4)
    pressed = emulator.ram.copy()
    emulator.set_state(state)
    emulator.run([0, 0], wait + 32)
    return bool((emulator.ram != pressed).any())


def test_froggers_frog_moves_after_reset_and_the_intro(imported: Path) -> None:
    from retrokit.host.emulator import Emulator

    frogger = Path(ale_py.__file__).parent / "roms" / "frogger.bin"
    with Emulator("Atari2600", frogger) as emulator:
        assert emulator.options() == {}  # stable-retro's stella declares no core option to set
        power_on = emulator.get_state()
        # Before RESET the game is on its attract screen: no joystick input on either port does anything.
        assert not _frog_moves(emulator, power_on, 600)
        emulator.run([emulator.system.mask(["RESET"]), 0], 5)
        started = emulator.get_state()
        # Then the intro plays for about 7 seconds (440 frames) before the frog takes input; then it hops.
        assert not _frog_moves(emulator, started, 300)
        assert _frog_moves(emulator, started, 480)
