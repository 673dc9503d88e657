"""PettingZoo envs of the two-player test cartridge: conformance and per-player rewards."""

from __future__ import annotations

import numpy as np
import pytest
from pettingzoo.test import api_test, parallel_api_test, parallel_seed_test, seed_test

from retrokit.envs import multiplayer
from retrokit.errors import InvalidArgumentError

DASHER = "Dasher-Genesis"
OPTIONS = {"frameskip": 4, "sticky_prob": 0.25, "max_episode_steps": 60}


def make_parallel(**extra):
    return multiplayer.parallel_env(DASHER, **{**OPTIONS, **extra})


@pytest.mark.parametrize("action_type", ["all", "filtered", "discrete", "multi_discrete"])
def test_parallel_api_test_passes(action_type: str) -> None:
    env = make_parallel(action_type=action_type)
    parallel_api_test(env, num_cycles=80)
    env.close()


def test_parallel_seed_test_passes() -> None:
    parallel_seed_test(make_parallel)


def test_aec_form_passes_the_api_and_seed_tests() -> None:
    env = multiplayer.env(DASHER, **OPTIONS)
    api_test(env, num_cycles=40)
    env.close()
    seed_test(lambda: multiplayer.env(DASHER, **OPTIONS), num_cycles=40)


def test_spaces_are_the_same_object_every_call() -> None:
    env = make_parallel()
    assert env.observation_space("player_1") is env.observation_space("player_1")
    assert env.action_space("player_2") is env.action_space("player_2")
    env.close()


def right(env, agent: str, jump: bool = False) -> np.ndarray:
    return env._env.actions.press(["RIGHT", "B"] if jump else ["RIGHT"])


def test_each_player_is_rewarded_for_its_own_progress() -> None:
    env = make_parallel(action_type="all", max_episode_steps=None)
    _observations, infos = env.reset(seed=0)
    assert infos["player_2"]["p2_state"] == 0  # the two-player state has player 2 in the game
    idle = np.zeros(env.action_space("player_1").n, dtype=np.int8)
    totals = {"player_1": 0.0, "player_2": 0.0}
    for _ in range(25):  # only player 2 runs
        _, rewards, _terminations, _, infos = env.step({"player_1": idle, "player_2": right(env, "player_2")})
        for agent, reward in rewards.items():
            totals[agent] += reward
    assert totals["player_2"] > 0 and totals["player_1"] == 0
    assert infos["player_2"]["p2_x"] > infos["player_1"]["p1_x"]
    env.close()


def test_one_player_games_are_refused() -> None:
    with pytest.raises(InvalidArgumentError, match="two or more players"):
        multiplayer.parallel_env("Airstriker-Genesis")


def test_players_option_is_refused() -> None:
    with pytest.raises(InvalidArgumentError, match="no 'players' option"):
        multiplayer.parallel_env(DASHER, players=2)
