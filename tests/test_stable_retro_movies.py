"""Movies of a game in a folder laid out as stable-retro's experimental games are, both ways.

stable-retro names a game by its integration folder: ``-v0`` for its stable games, none for its 58 experimental
(and contrib) ones, and writes that name as a movie's ``GameName``, by which its player looks the game up. No
commercial ROM is here, so the experimental game is one of our cartridges, Hopper-Nes, in a folder of stable-retro's
experimental layout (``Hopper-Nes/``: data.json, metadata.json, scenario.json, rom.sha, the ROM, a state), found by
retrokit through ``RETROKIT_GAMES`` and by stable-retro as a custom path. A random agent under ``action_type="all"``
presses the NES's unnamed RetroPad id 1 at once: stable-retro's recording drops that bit, and so does retrokit's.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
import pytest
from stable_retro_game import found_by_both, write_integration

import retrokit
from retrokit.data.games import find_game, stable_retro_name
from retrokit.movie import play, read_bk2

stable_retro = pytest.importorskip("stable_retro")

GAME = "Hopper-Nes"
STEPS = 150  # random steps of the recorded episode: the hopper moves, jumps and scores or dies on the way


@pytest.fixture(scope="module")
def experimental(tmp_path_factory: pytest.TempPathFactory):
    """A folder holding ``Hopper-Nes/`` as stable-retro's experimental games are laid out, searched by both."""
    root = tmp_path_factory.mktemp("experimental")
    integration = write_integration(find_game(GAME), root, name=GAME)
    with found_by_both(root):
        yield integration


@pytest.fixture(scope="module")
def recorded(experimental, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[np.ndarray], int]:
    """retrokit's movie of a random agent on the experimental game, the screens it showed, and how often id 1 was on."""
    folder = tmp_path_factory.mktemp("movies")
    rng = np.random.default_rng(0)
    with retrokit.make(GAME, state=experimental.state, action_type="all", record=folder) as env:
        assert env.unwrapped.game.folders[0] == experimental.folder  # the experimental folder's game, not games/'s
        env.reset(seed=0)
        screens, unnamed = [], 0
        for _ in range(STEPS):
            action = (rng.random(len(env.buttons)) < 0.3).astype(np.int8)
            unnamed += int(action[1])
            screens.append(env.step(action)[0].copy())
    (path,) = folder.glob("*.bk2")
    return path, screens, unnamed


def test_stable_retro_names_an_experimental_game_by_its_folder(experimental) -> None:
    assert stable_retro_name(GAME) == GAME == experimental.folder.name
    assert GAME in stable_retro.data.list_games(stable_retro.data.Integrations.CUSTOM_ONLY)


def test_every_game_stable_retro_lists_gets_its_name() -> None:
    # The wheel's 1,000-odd games: its stable ones with -v0, its experimental and contrib ones without.
    names = stable_retro.data.list_games(stable_retro.data.Integrations.ALL)
    experimental = stable_retro.data.list_games(stable_retro.data.Integrations.EXPERIMENTAL_ONLY)
    assert len(names) > 1000 and experimental and not any(n.endswith("-v0") for n in experimental)
    assert [n for n in names if stable_retro_name(n) != n] == []


def test_stable_retro_opens_and_plays_the_movie(recorded) -> None:
    path, screens, unnamed = recorded
    assert unnamed > STEPS // 10  # the agent pressed id 1 often: every such frame was recorded, without it
    movie = stable_retro.Movie(str(path))
    assert (movie.get_game(), movie.players) == (GAME, 1)
    # Its player's way: the game by the movie's GameName (here a custom path's, as experimental/ is the wheel's).
    env = stable_retro.make(movie.get_game(), state=stable_retro.State.NONE, render_mode=None,
                            inttype=stable_retro.data.Integrations.CUSTOM_ONLY,
                            use_restricted_actions=stable_retro.Actions.ALL, players=movie.players)  # fmt: skip
    try:
        emulator = env.unwrapped.em
        emulator.set_state(movie.get_state())
        buttons = env.unwrapped.buttons
        ours = read_bk2(path).frames
        for frame, screen in enumerate(screens):
            assert movie.step(), f"stable-retro's movie ended at frame {frame}"
            keys = [movie.get_key(i, 0) for i in range(len(buttons))]
            assert keys == [bool(ours[frame][0] >> i & 1) for i in range(len(buttons))], f"frame {frame}"
            assert not keys[1]  # the unnamed id: dropped
            emulator.set_button_mask(np.array(keys, dtype=np.uint8), 0)
            emulator.step()
            assert np.array_equal(emulator.get_screen(), screen), f"frame {frame}"
        assert not movie.step()
    finally:
        env.close()
    assert len({s.tobytes() for s in screens}) > STEPS // 4  # a game in motion, not one screen


def test_stable_retros_movie_of_the_experimental_game_plays_in_retrokit(experimental, tmp_path: Path) -> None:
    env = stable_retro.make(GAME, inttype=stable_retro.data.Integrations.CUSTOM_ONLY, render_mode=None,
                            use_restricted_actions=stable_retro.Actions.ALL, record=str(tmp_path))  # fmt: skip
    rng = np.random.default_rng(1)
    try:
        env.reset(seed=0)
        screens = [env.unwrapped.em.get_screen().copy()]  # its movie's first frame is the one its reset ran
        for _ in range(60):
            screens.append(env.step((rng.random(len(env.unwrapped.buttons)) < 0.3).astype(np.int8))[0].copy())
        env.unwrapped.stop_record()
    finally:
        env.close()
    (path,) = tmp_path.glob("*.bk2")
    movie = read_bk2(path)
    assert movie.game == GAME and "GameName Hopper-Nes\n" in unzip_member(path, "Header.txt")
    assert first_difference(list(play(path)), screens) is None


def unzip_member(path: Path, member: str) -> str:
    with zipfile.ZipFile(path) as archive:
        return archive.read(member).decode()


def test_a_pc_engine_movie_holds_i_ii_and_run_and_replays(tmp_path: Path) -> None:
    # Skipper, our PC Engine cartridge: I jumps, RUN starts. The movie holds them (record= raised at the first
    # press before) and retrokit replays it to the screens the episode showed; stable-retro opens it too.
    names = [["RUN"]] * 3 + [[]] * 30 + [["RIGHT", "I"]] * 40 + [["II", "LEFT"]] * 20 + [["I"]] * 30
    with retrokit.make("Skipper-PCEngine", action_type="all", record=tmp_path) as env:
        env.reset(seed=0)
        system = env.unwrapped.emulator.system
        screens = [env.step([b in now for b in env.buttons])[0].copy() for now in names]
    (path,) = tmp_path.glob("*.bk2")
    frames = read_bk2(path).frames
    assert frames == [(system.mask(now),) for now in names]
    assert first_difference(list(play(path)), screens) is None
    assert len({s.tobytes() for s in screens}) > 10  # I and RUN moved the game
    movie = stable_retro.Movie(str(path))
    assert sum(1 for _ in iter(movie.step, False)) == len(names)


def first_difference(ours: list[np.ndarray], theirs: list[np.ndarray]) -> int | None:
    assert len(ours) == len(theirs)
    return next((i for i, (a, b) in enumerate(zip(ours, theirs)) if not np.array_equal(a, b)), None)
