"""stable-retro's conveniences on RetroEnv: buttons, get_action_meaning, get_ram, load_state, -v0 names."""

from __future__ import annotations

import numpy as np
import pytest

import retrokit
from retrokit.data.games import find_game
from retrokit.data.states import read_state
from retrokit.errors import StateNotFoundError
from retrokit.movie.bk2 import read_bk2

GENESIS_BUTTONS = ["B", "A", "MODE", "START", "UP", "DOWN", "LEFT", "RIGHT", "C", "Y", "X", "Z"]


@pytest.fixture
def dasher():
    env = retrokit.make("Dasher-Genesis", action_type="all")
    yield env
    env.close()


def test_buttons_are_stable_retros_names_in_its_order(dasher) -> None:
    assert dasher.buttons == GENESIS_BUTTONS


@pytest.mark.parametrize(
    "action_type,action,meaning",
    [
        pytest.param("all", np.eye(12, dtype=np.int8)[7] + np.eye(12, dtype=np.int8)[0], ["B", "RIGHT"], id="all"),
        pytest.param("filtered", np.ones(12, dtype=np.int8), [], id="filtered_drops_impossible_combinations"),
        pytest.param("discrete", 0, [], id="discrete_noop"),
        # stable-retro's numbering: the third group's combinations sorted by mask, B (bit 0) first.
        pytest.param("multi_discrete", np.array([2, 2, 1]), ["B", "DOWN", "RIGHT"], id="multi_discrete"),
    ],
)
def test_get_action_meaning_names_the_buttons_the_console_sees(action_type: str, action, meaning: list[str]) -> None:
    env = retrokit.make("Airstriker-Genesis", action_type=action_type)
    if action_type == "multi_discrete":  # Genesis's groups: [] UP DOWN, [] LEFT RIGHT, then B/A/C combinations
        assert env.action_space.nvec.tolist() == [3, 3, 14]
    assert env.get_action_meaning(action) == meaning
    env.close()


def test_get_action_meaning_gives_one_list_per_player() -> None:
    env = retrokit.make("Dasher-Genesis", action_type="all", players=2)
    action = np.zeros(24, dtype=np.int8)
    action[[6, 12 + 3]] = 1  # player 1 LEFT, player 2 START
    assert env.get_action_meaning(action) == [["LEFT"], ["START"]]
    env.close()


def test_get_ram_is_a_copy_of_the_system_ram(dasher) -> None:
    dasher.reset(seed=0)
    ram = dasher.get_ram()
    assert ram.dtype == np.uint8 and ram.shape == (0x10000,)
    assert ram[0x20 ^ 1] == dasher.unwrapped.emulator.peek(0xFF0020, "|u1")  # Genesis RAM is byte-swapped
    ram[:] = 0
    assert dasher.get_ram().any()  # changing the copy changes nothing


def test_load_state_starts_the_next_episode_there(dasher) -> None:
    _, info = dasher.reset(seed=0)
    assert (info["zone"], info["act"]) == (0, 0)
    first = dasher.reset(seed=0)[0]
    dasher.load_state("Zone2.Act1")
    obs, info = dasher.reset(seed=0)
    assert (info["zone"], info["act"]) == (1, 0) and dasher.state_name == "Zone2.Act1"
    assert not np.array_equal(obs, first)  # the first observation is the new state's too
    dasher.load_state("Zone1.Act1")
    assert np.array_equal(dasher.reset(seed=0)[0], first)


def test_movies_recorded_after_load_state_start_from_the_new_state(tmp_path) -> None:
    env = retrokit.make("Dasher-Genesis", record=tmp_path)
    env.reset(seed=0)
    env.step(env.action_space.sample())
    env.load_state("Zone2.Act1")
    env.reset(seed=0)
    env.step(env.action_space.sample())
    env.close()
    movies = sorted(tmp_path.glob("*.bk2"))
    assert [m.name.rsplit("-", 1)[0] for m in movies] == ["Dasher-Genesis-Zone1.Act1", "Dasher-Genesis-Zone2.Act1"]
    game = find_game("Dasher-Genesis")
    for movie, state in zip(movies, ("Zone1.Act1", "Zone2.Act1")):
        assert read_bk2(movie).state == read_state(game.state_path(state))


def test_load_state_of_an_unknown_name_says_so(dasher) -> None:
    with pytest.raises(StateNotFoundError, match="Did you mean 'Zone2.Act2'"):
        dasher.load_state("Zone2.Act")


def test_stable_retro_game_names_with_v0_are_accepted() -> None:
    env = retrokit.make("Airstriker-Genesis-v0")
    assert env.game.name == "Airstriker-Genesis"
    env.close()
