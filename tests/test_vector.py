"""The threaded vector env gives exactly what N single envs give."""

from __future__ import annotations

import numpy as np
import pytest

import retrokit
from retrokit.errors import InvalidArgumentError

OPTIONS = {"frameskip": 4, "sticky_prob": 0.25, "max_episode_steps": 25, "action_type": "discrete"}


def actions_for(step: int, n: int) -> np.ndarray:
    rng = np.random.default_rng(step)
    return rng.integers(0, 126, n)


def test_vector_equals_single_envs_through_autoreset() -> None:
    n, seed, steps = 2, 10, 60
    vec = retrokit.make_vec("Airstriker-Genesis", n, **OPTIONS)
    singles = [retrokit.make("Airstriker-Genesis", **OPTIONS) for _ in range(n)]
    obs, infos = vec.reset(seed=seed)
    single_obs = [env.reset(seed=seed + i)[0] for i, env in enumerate(singles)]
    assert all((obs[i] == single_obs[i]).all() for i in range(n))
    done = [False] * n
    resets = 0
    for step in range(steps):
        acts = actions_for(step, n)
        obs, rewards, terms, truncs, infos = vec.step(acts)
        for i, env in enumerate(singles):
            if done[i]:  # next-step autoreset: this step resets, reward 0
                expected_obs, info = env.reset()
                expected = (expected_obs, 0.0, False, False, info)
                resets += 1
            else:
                expected = env.step(acts[i])
            assert (obs[i] == expected[0]).all(), (step, i)
            assert rewards[i] == expected[1] and terms[i] == expected[2] and truncs[i] == expected[3]
            assert infos["score"][i] == expected[4]["score"] and infos["lives"][i] == expected[4]["lives"]
            done[i] = expected[2] or expected[3]
    assert resets >= n  # the 25-step limit forced autoresets along the way
    vec.close()
    for env in singles:
        env.close()


def test_vector_spaces_are_batched() -> None:
    vec = retrokit.make_vec("Airstriker-Genesis", 3, frameskip=4)
    assert vec.num_envs == 3
    assert vec.observation_space.shape == (3, 224, 320, 3)
    assert vec.single_observation_space.shape == (224, 320, 3)
    vec.close()


def test_vector_needs_at_least_one_env() -> None:
    with pytest.raises(InvalidArgumentError, match="num_envs of 1 or more"):
        retrokit.make_vec("Airstriker-Genesis", 0)
