"""Every kind of env pickles as its arguments, and unpickles into a fresh env that plays (Dasher).

What users pickle envs for: Gymnasium's AsyncVectorEnv and SuperSuit's
``concat_vec_envs_v1(..., num_cpus=2)`` send them to worker processes.
"""

from __future__ import annotations

import copy
import functools
import pickle

import gymnasium
import numpy as np
import pytest
from gymnasium.utils import EzPickle

import retrokit
from retrokit.data.games import find_game
from retrokit.envs import multiplayer, sonic

GAME = "Dasher-Genesis"
RAM = {"obs_type": "ram", "frameskip": 4}


def round_trip(env):
    return pickle.loads(pickle.dumps(env))


def play(env, seed: int = 3, steps: int = 20) -> list[tuple[float, bytes]]:
    """The rewards and observations of a seeded episode's start under a seeded random action sequence."""
    env.reset(seed=seed)
    env.action_space.seed(seed)
    steps_taken = [env.step(env.action_space.sample()) for _ in range(steps)]
    return [(float(reward), obs.tobytes()) for obs, reward, *_ in steps_taken]


@pytest.mark.parametrize(
    "arguments",
    [
        {"game": GAME, **RAM},
        {"game": GAME, "obs_type": "rgb", "action_type": "discrete"},
        {"game": GAME, "state": retrokit.State.NONE, **RAM},
    ],
    ids=["ram", "rgb-discrete", "power-on"],
)
def test_a_retro_env_round_trips_into_a_fresh_env_that_plays_the_same(arguments: dict) -> None:
    env = retrokit.make(**arguments)
    before = play(env)
    copy = round_trip(env)
    assert isinstance(copy, EzPickle) and copy is not env
    assert copy.emulator is not env.emulator
    assert copy.observation_space == env.observation_space and copy.action_space == env.action_space
    assert (copy.frameskip, copy.obs_type, copy.state_name) == (env.frameskip, env.obs_type, env.state_name)
    assert play(copy) == before  # first episodes both: a console reset keeps some RAM, so later ones may differ
    env.close()
    copy.close()


def test_the_copy_starts_fresh_not_where_the_original_was() -> None:
    env = retrokit.make(GAME, **RAM)
    first, _ = env.reset(seed=0)
    for _ in range(30):
        env.step(env.action_space.sample())
    assert not np.array_equal(env.get_ram(), first)
    copy = round_trip(env)
    obs, _ = copy.reset(seed=0)
    assert np.array_equal(obs, first)  # the episode's start, not the original's frame 120
    env.close()
    copy.close()


def test_deepcopy_makes_a_fresh_env_too() -> None:
    # SuperSuit's concat_vec_envs_v1 without num_cpus deep-copies the env it is given.
    env = retrokit.make(GAME, **RAM)
    twin = copy.deepcopy(env)
    assert twin.emulator is not env.emulator and play(twin) == play(env)
    env.close()
    twin.close()


def test_a_game_object_and_a_scenario_dict_as_arguments_pickle() -> None:
    game = find_game(GAME)
    game.fields  # noqa: B018 - read the data file, whose read-only views do not pickle themselves
    scenario = {"reward": "delta(p1_x)", "done": "game_mode == 3"}
    env = retrokit.make(game, "Zone1.Act1", scenario, **RAM)
    copy = round_trip(env)
    assert copy.game == game and copy.game.fields.keys() == game.fields.keys()
    assert play(copy) == play(env)
    env.close()
    copy.close()


def test_the_sonic_preset_wrappers_pickle_with_their_env() -> None:
    # No Sonic ROM here: the preset's own wrappers, on Dasher with the same settings.
    env = sonic.AllowBacktracking(sonic.Discretizer(retrokit.make(GAME, action_type="all", **RAM), sonic.ACTIONS))
    copy = round_trip(env)
    assert isinstance(copy, sonic.AllowBacktracking) and copy.action_space == gymnasium.spaces.Discrete(7)
    assert play(copy) == play(env)
    env.close()
    copy.close()


def test_a_vector_env_round_trips_into_a_fresh_one() -> None:
    vec = retrokit.make_vec(GAME, 2, threads=2, **RAM)
    copy = round_trip(vec)
    assert copy.num_envs == 2 and copy.threads == 2 and copy.envs[0] is not vec.envs[0]
    obs, _ = copy.reset(seed=0)
    expected, _ = vec.reset(seed=0)
    assert np.array_equal(obs, expected)
    actions = np.ones((2, 12), dtype=np.int8)
    assert np.array_equal(copy.step(actions)[0], vec.step(actions)[0])
    vec.close()
    copy.close()


def test_a_vector_env_of_lambdas_does_not_pickle() -> None:
    vec = retrokit.ThreadedVectorEnv([lambda: retrokit.make(GAME, **RAM)])
    with pytest.raises((pickle.PicklingError, AttributeError)):
        pickle.dumps(vec)
    vec.close()


@pytest.mark.parametrize("make", [multiplayer.parallel_env, multiplayer.env], ids=["parallel", "aec"])
def test_the_pettingzoo_envs_round_trip(make) -> None:
    env = make(GAME, **RAM)
    copy = round_trip(env)
    assert type(copy) is type(env) and copy.possible_agents == env.possible_agents
    copy.reset(seed=0)
    if make is multiplayer.parallel_env:
        _, rewards, *_ = copy.step({a: copy.action_space(a).sample() for a in copy.agents})
        assert set(rewards) == set(copy.possible_agents)
    else:
        for _ in range(4):
            copy.step(copy.action_space(copy.agent_selection).sample())
        assert copy.agent_selection in copy.possible_agents
    env.close()
    copy.close()


def test_supersuits_concat_with_two_processes() -> None:
    ss = pytest.importorskip("supersuit", reason="SuperSuit is not installed: pip install supersuit")
    parallel = multiplayer.parallel_env(GAME, max_episode_steps=30, **RAM)
    vec = ss.concat_vec_envs_v1(ss.pettingzoo_env_to_vec_env_v1(parallel), 2, num_cpus=2, base_class="gymnasium")
    try:
        assert vec.num_envs == 4  # 2 copies x 2 players
        obs, _ = vec.reset(seed=0)
        assert obs.shape == (4, *parallel.observation_space("player_1").shape)
        truncated_once = False
        for _ in range(31):
            _, rewards, _, truncations, _ = vec.step(np.stack([vec.action_space.sample() for _ in range(4)]))
            truncated_once |= bool(truncations.all())
        assert rewards.shape == (4,) and truncated_once  # the copies played 30 steps in their processes
    finally:
        vec.close()


def test_gymnasiums_async_vector_env_over_retrokit_envs() -> None:
    make = functools.partial(retrokit.make, GAME, max_episode_steps=10, **RAM)
    vec = gymnasium.vector.AsyncVectorEnv([make, make], context="spawn")
    try:
        obs, _ = vec.reset(seed=[1, 1])
        assert obs.shape == (2, 65536) and np.array_equal(obs[0], obs[1])
        for _ in range(10):
            _, _, _, truncations, _ = vec.step(np.ones((2, 12), dtype=np.int8))
        assert truncations.all()
    finally:
        vec.close()
