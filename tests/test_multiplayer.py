"""PettingZoo envs of the two-player test cartridge: conformance and per-player rewards."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from pettingzoo.test import api_test, parallel_api_test, parallel_seed_test, seed_test

from retrokit.data.statecheck import remember_written
from retrokit.data.states import write_state
from retrokit.envs import multiplayer
from retrokit.envs.env import RetroEnv
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


@pytest.mark.parametrize(
    "action_type,bad,message",
    [
        pytest.param("discrete", lambda space: space.n, "from 0 to", id="discrete_past_the_end"),
        pytest.param("discrete", lambda space: -1, "from 0 to", id="discrete_negative"),
        pytest.param("multi_discrete", lambda space: space.nvec, "choice 0", id="multi_discrete_past_the_end"),
        pytest.param("multi_discrete", lambda space: space.sample() + 0.5, "whole numbers", id="multi_discrete_floats"),
        pytest.param("all", lambda space: np.zeros(space.n + 1, dtype=np.int8), "12 items", id="buttons_too_many"),
        pytest.param("filtered", lambda space: np.zeros(space.n - 1, dtype=np.int8), "12 items", id="buttons_too_few"),
    ],
)
def test_one_players_action_outside_its_space_is_refused(action_type: str, bad, message: str) -> None:
    # Joined into one action, it would otherwise press buttons of the other player.
    env = make_parallel(action_type=action_type)
    env.reset(seed=0)
    space = env.action_space("player_1")
    with pytest.raises(InvalidArgumentError, match=message):
        env.step({"player_1": bad(space), "player_2": env.action_space("player_2").sample()})
    env.close()


def test_one_player_games_are_refused() -> None:
    with pytest.raises(InvalidArgumentError, match="two or more players"):
        multiplayer.parallel_env("Airstriker-Genesis")


def test_players_option_is_refused() -> None:
    with pytest.raises(InvalidArgumentError, match="no 'players' option"):
        multiplayer.parallel_env(DASHER, players=2)


# --- a player out of the game for good ------------------------------------------------------------


@pytest.fixture(scope="module")
def p2_last_life(tmp_path_factory) -> Path:
    """Dasher's two-player start, with player 2 dying on its last life: out (state 2) 120 frames later."""
    env = RetroEnv(DASHER, "Zone1.Act1.2P", players=2)
    env.reset(seed=0)
    for name, value in (("p2_lives", 0), ("p2_state", 1), ("p2_timer", 0)):
        env.reader.write(name, value)
    state = env.emulator.get_state()
    # Written here from a core, as retrokit's own tools write states: loading it needs no probe (those are
    # tests/test_trust.py's and test_hostile_states.py's), which saves a child process.
    remember_written(env.game, state)
    path = write_state(tmp_path_factory.mktemp("states") / "P2LastLife.state", state)
    env.close()
    return path


def play_until_p2_is_out(env, seed: int = 0):
    """Step with player 1 idle; return the step index and results at which player 2 left."""
    env.reset(seed=seed)
    for i in range(100):
        actions = {agent: env.action_space(agent).sample() * 0 for agent in env.agents}
        results = env.step(actions)
        if "player_2" not in env.agents:
            return i, results
    raise AssertionError("player 2 never left the game")


def test_a_player_out_of_lives_is_terminated_and_leaves_agents(p2_last_life: Path) -> None:
    env = make_parallel(state=p2_last_life, action_type="all", max_episode_steps=None)
    i, (_, rewards, terminations, truncations, infos) = play_until_p2_is_out(env)
    assert i == 30  # after the death animation: 120 frames, 4 a step, and the frame the state was saved in
    assert infos["player_2"]["p2_state"] == 2 and infos["player_1"]["p1_state"] == 0
    assert terminations == {"player_1": False, "player_2": True} and not any(truncations.values())
    assert env.agents == ["player_1"]
    # Player 1 plays on alone; player 2 gets nothing more, and an action passed for it does nothing.
    for _ in range(5):
        observations, rewards, terminations, truncations, infos = env.step(
            {"player_1": right(env, "player_1"), "player_2": right(env, "player_2")}
        )
        assert set(observations) == set(rewards) == set(terminations) == set(infos) == {"player_1"}
    assert infos["player_1"]["p2_state"] == 2 and infos["player_1"]["p1_x"] > infos["player_1"]["p2_x"]
    env.close()


@pytest.mark.parametrize("action_type", ["filtered", "discrete"])
def test_parallel_api_test_passes_with_a_player_eliminated(p2_last_life: Path, action_type: str) -> None:
    env = make_parallel(state=p2_last_life, action_type=action_type, max_episode_steps=60)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        parallel_api_test(env, num_cycles=60)
    assert not [str(w.message) for w in caught if "dead" in str(w.message) or "Live agent" in str(w.message)]
    # The test's episodes really lost player 2 midway, with player 1 playing on: replay one.
    i, (_, _, terminations, truncations, _) = play_until_p2_is_out(env)
    assert 0 < i < 60 and env.agents == ["player_1"]
    assert terminations["player_2"] and not truncations["player_2"]
    env.close()


def test_aec_api_test_passes_with_a_player_eliminated(p2_last_life: Path) -> None:
    env = multiplayer.env(DASHER, **{**OPTIONS, "state": p2_last_life})
    api_test(env, num_cycles=60)
    # Replay: player 2 is terminated and leaves while player 1 is still playing.
    env.reset(seed=0)
    for agent in env.agent_iter(max_iter=200):
        if env.terminations.get("player_2"):
            break
        env.step(None if env.terminations[agent] or env.truncations[agent] else env.action_space(agent).sample())
    assert env.terminations["player_2"] and not env.terminations["player_1"] and not env.truncations["player_1"]
    env.close()


def test_the_episode_ends_when_every_player_is_out(p2_last_life: Path) -> None:
    scenario = {"rewards": ["p1_x", "p2_x"], "dones": ["p1_state == 2", "p2_state == 2"]}  # no 'done' of its own
    env = RetroEnv(DASHER, p2_last_life, scenario, players=2, frameskip=4)
    env.reset(seed=0)
    env.reader.write("p1_lives", 0)  # player 1 on its last life too, about to be killed
    env.reader.write("p1_state", 1)
    env.reader.write("p1_timer", 0)
    dones = []
    for _ in range(40):
        _, _, terminated, _, info = env.step(env.action_space.sample() * 0)
        dones.append(info["dones"])
        if terminated:
            break
    assert terminated and dones[-1] == (True, True) and (False, False) in dones
    env.close()
