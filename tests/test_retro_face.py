"""``retrokit.retro`` against stable-retro itself: the same calls give the same frames, fields, movies and errors.

Both run in this process on Airstriker (stable-retro's emulators and retrokit's private core copies live side
by side). stable-retro's own scripts on the face are tests/test_retro_scripts.py.
"""

from __future__ import annotations

import gzip
import pickle
from pathlib import Path

import numpy as np
import pytest

from retrokit import retro
from retrokit.errors import (
    FieldNotFoundError,
    FileConflictError,
    GameNotFoundError,
    InvalidArgumentError,
    MovieError,
    StateError,
)

stable_retro = pytest.importorskip("stable_retro")

GAME = "Airstriker-Genesis"
STEPS = 600


def both(state_name: str = "DEFAULT", actions: str = "ALL", **kwargs):
    """stable-retro's env and the face's, made with the same arguments (no window)."""
    theirs = stable_retro.make(
        f"{GAME}-v0", state=getattr(stable_retro.State, state_name), render_mode=None,
        use_restricted_actions=getattr(stable_retro.Actions, actions), **kwargs,
    )  # fmt: skip
    ours = retro.make(
        GAME, state=getattr(retro.State, state_name), render_mode=None,
        use_restricted_actions=getattr(retro.Actions, actions), **kwargs,
    )  # fmt: skip
    return theirs, ours


def random_buttons(count: int, seed: int = 0) -> list[np.ndarray]:
    """Button arrays that press fire most of the time and wander, so the ship scores and dies."""
    rng = np.random.default_rng(seed)
    return [(rng.random(12) < 0.3).astype(np.int8) | (np.arange(12) == 0) * (i % 8 < 4) for i in range(count)]


def test_a_trace_from_the_default_state_matches_stable_retro() -> None:
    theirs, ours = both("DEFAULT", "DISCRETE")
    try:
        assert ours.action_space == theirs.action_space and ours.observation_space == theirs.observation_space
        assert (ours.reset()[0] == theirs.reset()[0]).all()
        rng = np.random.default_rng(1)
        seen = set()
        for step in range(STEPS):
            action = int(rng.integers(ours.action_space.n))
            mine, reference = ours.step(action), theirs.step(action)
            assert (mine[0] == reference[0]).all(), f"screen at step {step}"
            assert mine[1:4] == reference[1:4] and mine[4] == reference[4], f"step {step}"
            assert (ours.get_ram() == theirs.get_ram()).all(), f"RAM at step {step}"
            seen.add(tuple(mine[4].values()))
        assert len(seen) > 2  # a game in motion (it scores), not a frozen screen
        assert ours.statename == theirs.statename == "Level1.state"
        assert ours.system == theirs.system and ours.buttons == theirs.buttons
        assert ours.num_buttons == theirs.num_buttons and ours.gamename == GAME
    finally:
        theirs.close()
        ours.close()


def test_a_trace_from_power_on_matches_stable_retro() -> None:
    """From power-on nothing presses reset: the console is two frames in at make (stable-retro's emulator runs one as
    it loads the game, its env one more), reset() runs one more from wherever it is, and every frame matches."""
    theirs, ours = both("NONE", "ALL")
    try:
        assert ours.initial_state is None and ours.statename is None
        assert ours.emulator.frame == 2
        assert (ours.reset()[0] == theirs.reset()[0]).all() and ours.emulator.frame == 3
        for episode in range(2):  # the second reset goes on from where the console is, as stable-retro's
            for step, action in enumerate(random_buttons(STEPS // 2, seed=episode)):
                mine, reference = ours.step(action), theirs.step(action)
                assert (mine[0] == reference[0]).all(), f"screen at step {step} of episode {episode}"
                assert mine[1:] == reference[1:], f"step {step} of episode {episode}"
                assert (ours.get_ram() == theirs.get_ram()).all(), f"RAM at step {step} of episode {episode}"
            assert (ours.reset()[0] == theirs.reset()[0]).all()
        assert ours.emulator.frame == 3 + STEPS + 2  # and a frame at each of the two resets
    finally:
        theirs.close()
        ours.close()


def test_retroemulator_runs_a_frame_as_it_loads_as_stable_retros(airstriker_rom: Path) -> None:
    ours = retro.RetroEmulator(airstriker_rom)
    try:
        assert ours.emulator.frame == 1 and ours.get_screen().shape[2] == 3
        ours.set_button_mask(np.ones(12))
        ours.step()
        assert ours.emulator.held()[0] == 0xFFF
    finally:
        ours.close()


def test_env_data_reads_and_writes_fields_as_stable_retro() -> None:
    theirs, ours = both()
    try:
        theirs.reset()
        ours.reset()
        for action in random_buttons(60):
            theirs.step(action)
            ours.step(action)
        assert ours.data.lookup_all() == theirs.data.lookup_all()
        for name in theirs.data.lookup_all():
            assert ours.data.lookup_value(name) == ours.data[name] == theirs.data.lookup_value(name)
        ours.data.set_value("lives", 1)
        theirs.data.set_value("lives", 1)
        ours.data["score"] = theirs.data["score"] = 5
        mine, reference = ours.step(random_buttons(1)[0]), theirs.step(random_buttons(1)[0])
        assert mine[4] == reference[4] and mine[4]["lives"] == 1
        with pytest.raises(FieldNotFoundError, match="Did you mean 'lives'"):
            ours.data.lookup_value("live")
        with pytest.raises(AttributeError, match="env.get_ram"):
            ours.data.memory  # noqa: B018
    finally:
        theirs.close()
        ours.close()


def test_a_saved_state_replays_after_em_set_state_and_data_reset() -> None:
    """determinism.py's pattern: em.get_state, em.set_state, data.reset, data.update_ram, then the same steps again."""
    env = retro.make(GAME, render_mode=None, use_restricted_actions=retro.Actions.ALL)
    try:
        env.reset()
        actions = random_buttons(150, seed=3)
        start = env.em.get_state()
        first = [env.step(a)[1:] for a in actions]
        assert sum(r[0] for r in first) > 0
        env.em.set_state(start)
        env.data.reset()
        env.data.update_ram()
        assert [env.step(a)[1:] for a in actions] == first
        assert len(env.em.get_screen().shape) == 3 and env.em.get_screen_rate() > 59
    finally:
        env.close()


def test_a_movie_recorded_here_plays_in_stable_retro(tmp_path: Path) -> None:
    path = tmp_path / "ours.bk2"
    env = retro.make(GAME, render_mode=None, use_restricted_actions=retro.Actions.ALL)
    env.record_movie(str(path))
    env.reset()
    infos = [env.step(a)[4] for a in random_buttons(200, seed=4)]
    env.stop_record()
    env.close()
    movie = stable_retro.Movie(str(path))
    movie.step()  # the frame reset ran
    assert movie.get_game() == f"{GAME}-v0" and movie.players == 1
    theirs = stable_retro.make(
        movie.get_game(), state=stable_retro.State.NONE, render_mode=None,
        use_restricted_actions=stable_retro.Actions.ALL,
    )  # fmt: skip
    try:
        theirs.initial_state = movie.get_state()
        theirs.reset()
        replayed = []
        while movie.step():
            keys = [movie.get_key(i, 0) for i in range(theirs.num_buttons)]
            replayed.append(theirs.step(keys)[4])
        assert replayed == infos
    finally:
        theirs.close()


def test_a_movie_stable_retro_recorded_plays_here(tmp_path: Path) -> None:
    path = tmp_path / "theirs.bk2"
    theirs = stable_retro.make(f"{GAME}-v0", render_mode=None, use_restricted_actions=stable_retro.Actions.ALL)
    theirs.record_movie(str(path))
    theirs.reset()
    expected = []
    for action in random_buttons(200, seed=5):
        theirs.step(action)
        expected.append(theirs.get_ram().copy())
    theirs.stop_record()
    theirs.close()
    movie = retro.Movie(path)
    assert movie.step() and movie.get_game() == f"{GAME}-v0"
    env = retro.make(movie.get_game(), state=retro.State.NONE, render_mode=None, use_restricted_actions=retro.Actions.ALL)
    try:
        env.initial_state = movie.get_state()  # checked before any reset loads it
        env.reset()
        got = []
        while movie.step():
            env.step([movie.get_key(i, 0) for i in range(env.num_buttons)])
            got.append(env.get_ram().copy())
        assert len(got) == len(expected) and all((a == b).all() for a, b in zip(got, expected))
    finally:
        env.close()


def test_recording_again_replaces_only_a_movie_this_process_recorded(tmp_path: Path) -> None:
    env = retro.make(GAME, render_mode=None)
    try:
        for _ in range(2):  # brute.py records best.bk2 again at each better run
            env.record_movie(tmp_path / "best.bk2")
            env.reset()
            env.step(env.action_space.sample())
            env.stop_record()
        assert sum(1 for _ in _frames(retro.Movie(tmp_path / "best.bk2"))) == 2
        (tmp_path / "mine.bk2").write_bytes(b"the user's file")
        with pytest.raises(FileConflictError, match="mine.bk2"):
            env.record_movie(tmp_path / "mine.bk2")
        assert (tmp_path / "mine.bk2").read_bytes() == b"the user's file"
    finally:
        env.close()


def _frames(movie: retro.Movie):
    while movie.step():
        yield movie.get_key(0)


def test_two_players_get_a_list_of_rewards() -> None:
    env = retro.make("Dasher-Genesis", players=2, render_mode=None, use_restricted_actions=retro.Actions.ALL)
    try:
        env.reset()
        _, reward, *_ = env.step(env.action_space.sample())
        assert isinstance(reward, list) and len(reward) == 2
        env.multi_rewards = False  # stable-retro 1.0.1's default: the first player's
        _, reward, *_ = env.step(env.action_space.sample())
        assert isinstance(reward, float)
    finally:
        env.close()


def test_data_lists_and_finds_games_as_stable_retro() -> None:
    assert f"{GAME}-v0" in retro.data.list_games()
    assert set(stable_retro.data.list_games()) <= set(retro.data.list_games(retro.data.Integrations.ALL))
    assert retro.data.list_states(f"{GAME}-v0") == stable_retro.data.list_states(f"{GAME}-v0")
    assert retro.data.list_scenarios(GAME) == ["scenario"]
    assert retro.data.get_file_path(GAME, "rom.sha") == stable_retro.data.get_file_path(f"{GAME}-v0", "rom.sha")
    assert retro.data.get_file_path("NoSuchGame-Genesis", "rom.sha") is None
    assert Path(retro.data.get_romfile_path(GAME)).samefile(stable_retro.data.get_romfile_path(f"{GAME}-v0"))
    with pytest.raises(GameNotFoundError, match="Airstriker-Genesis"):
        retro.data.list_states("Airstriker-Genesys")
    assert retro.get_romfile_system("x/rom.md") == stable_retro.get_romfile_system("x/rom.md") == "Genesis"
    with pytest.raises(AttributeError, match="no FBNeo"):
        retro.is_fbneo_game  # noqa: B018
    for escape in ("../../../../etc/passwd", "/etc/passwd"):
        with pytest.raises(InvalidArgumentError, match="leads out of"):
            retro.data.get_file_path(GAME, escape)
    with pytest.raises(AttributeError, match="retrokit validate"):
        retro.data.verify_hash  # noqa: B018


def test_a_custom_path_is_searched(tmp_path: Path, airstriker_dir: Path) -> None:
    folder = tmp_path / "MyStriker-Genesis"
    folder.mkdir()
    for name in ("rom.sha", "data.json", "scenario.json", "metadata.json", "Level1.state"):
        (folder / name).write_bytes((airstriker_dir / name).read_bytes())
    retro.data.Integrations.add_custom_path(tmp_path)
    try:
        assert "MyStriker-Genesis" in retro.data.list_games(retro.data.Integrations.CUSTOM)
        assert retro.data.list_states("MyStriker-Genesis") == ["Level1"]
    finally:
        retro.data.Integrations.clear_custom_paths()
    assert "MyStriker-Genesis" not in retro.data.list_games(retro.data.Integrations.ALL)


def test_the_env_pickles_as_stable_retro_arguments() -> None:
    env = retro.make(GAME, render_mode=None, use_restricted_actions=retro.Actions.DISCRETE)
    copy = pickle.loads(pickle.dumps(env))
    try:
        assert type(copy) is retro.RetroEnv and copy.action_space == env.action_space
    finally:
        copy.close()
        env.close()


# --- what retrokit cannot do, or will not take, fails in one line ------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "error", "says"),
    [
        ({"frameskip": 4}, InvalidArgumentError, "retrokit.make"),
        ({"use_restricted_actions": "discrete"}, InvalidArgumentError, "retro.Actions.FILTERED"),
        ({"obs_type": "ram"}, InvalidArgumentError, "retro.Observations.IMAGE"),
        ({"info": "other.json"}, InvalidArgumentError, "game's own data.json"),
        ({"inttype": "all"}, InvalidArgumentError, "Integrations.ALL"),
        ({"state": "Level9"}, Exception, "Level1"),
    ],
    ids=["retrokit-option", "actions-as-string", "obs-as-string", "other-info-file", "inttype-as-string", "no-such-state"],
)
def test_bad_arguments_fail_in_one_line(kwargs: dict, error: type[Exception], says: str) -> None:
    with pytest.raises(error) as caught:
        retro.make(GAME, render_mode=None, **kwargs)
    message = str(caught.value)
    assert says in message and "\n" not in message


def test_foreign_bytes_are_checked_before_they_reach_the_core(tmp_path: Path, airstriker_dir: Path) -> None:
    env = retro.make(GAME, render_mode=None)
    try:
        for junk in (b"\0" * 100, b"not a state" * 1000):
            with pytest.raises(StateError):
                env.em.set_state(junk)
            with pytest.raises(StateError):
                env.initial_state = junk
        dasher = next(Path(__file__).parent.parent.glob("games/Dasher-Genesis/Zone1.Act1.state"))
        with pytest.raises(StateError, match="Dasher"):  # another game's state, by its digest
            env.initial_state = gzip.decompress(dasher.read_bytes())
        env.initial_state = gzip.decompress((airstriker_dir / "Level1.state").read_bytes())
        env.reset()
    finally:
        env.close()


def test_bad_buttons_and_keys_fail_in_one_line(tmp_path: Path) -> None:
    env = retro.make(GAME, render_mode=None)
    try:
        with pytest.raises(InvalidArgumentError, match="players=2"):
            env.em.set_button_mask(np.ones(12), 5)
        with pytest.raises(InvalidArgumentError, match="at most 16"):
            env.em.set_button_mask(np.ones(10_000))
        with pytest.raises(AttributeError, match="no cheats"):
            env.em.add_cheat  # noqa: B018
    finally:
        env.close()
    movie = retro.Movie(tmp_path / "keys.bk2", True)
    for key, player in ((16, 0), (-1, 0), (0, 1)):
        with pytest.raises(MovieError, match="expected a key from 0 to 15"):
            movie.set_key(key, True, player)


@pytest.mark.parametrize(
    "content",
    [b"", b"PK\x03\x04 truncated", b"\x00" * 4096, b"Header.txt" * 10_000],
    ids=["empty", "truncated-zip", "zeros", "text"],
)
def test_a_corrupt_movie_fails_in_one_line(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "bad.bk2"
    path.write_bytes(content)
    with pytest.raises(MovieError) as caught:
        retro.Movie(path)
    assert "\n" not in str(caught.value) and "bad.bk2" in str(caught.value)


def test_a_movie_read_is_not_written_and_one_recorded_needs_its_game(tmp_path: Path) -> None:
    movie = retro.Movie(tmp_path / "new.bk2", True)
    with pytest.raises(MovieError, match="configure"):
        movie.step()
    with pytest.raises(GameNotFoundError):
        movie.configure("NoSuchGame-Genesis")
        movie.step()
    assert not (tmp_path / "new.bk2").exists()


REPO = Path(__file__).resolve().parent.parent
# One test cartridge per system family. The PC Engine's presses III and IV (turbo toggles) on its random frames:
# its screens match only because its descriptor leaves the turbo delay unanswered, as stable-retro does.
CARTRIDGES = ["Dasher-Genesis/rom.md", "Hopper-Nes/rom.nes", "Hopper-Sms/rom.sms", "Hopper-GameGear/rom.gg",
              "Trekker-GameBoy/rom.gb", "Trekker-GbColor/rom.gbc", "Skipper-Snes/rom.sfc",
              "Skipper-PCEngine/rom.pce"]  # fmt: skip


@pytest.mark.parametrize("rom", CARTRIDGES, ids=[c.split("/")[0] for c in CARTRIDGES])
def test_retroemulator_from_power_on_shows_stable_retros_screens(rom: str) -> None:
    import gc

    path = str(REPO / "games" / rom)
    theirs = stable_retro.RetroEmulator(path)
    ours = retro.RetroEmulator(path)
    try:
        rng = np.random.default_rng(0)
        for frame in range(150):
            buttons = (rng.random(12) < 0.2).astype(np.uint8) if frame >= 30 else np.zeros(12, np.uint8)
            theirs.set_button_mask(buttons)
            ours.set_button_mask(buttons)
            theirs.step()
            ours.step()
            if frame >= 4:  # stable-retro shows Genesis boot frames at 320x224 whatever the core draws
                assert (ours.get_screen() == theirs.get_screen()).all(), f"frame {frame}"
    finally:
        ours.close()
        del theirs
        gc.collect()  # stable-retro keeps one emulator a process


def test_ram_observations_are_stable_retros() -> None:
    theirs = stable_retro.make(f"{GAME}-v0", render_mode=None, obs_type=stable_retro.Observations.RAM)
    ours = retro.make(GAME, render_mode=None, obs_type=retro.Observations.RAM)
    try:
        assert ours.observation_space == theirs.observation_space
        assert (ours.reset()[0] == theirs.reset()[0]).all()
        for step, action in enumerate(random_buttons(60, seed=7)):
            assert (ours.step(action)[0] == theirs.step(action)[0]).all(), f"step {step}"
    finally:
        theirs.close()
        ours.close()
