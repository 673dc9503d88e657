"""The threaded vector env gives exactly what N single envs give."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

import retrokit
from retrokit.errors import InvalidArgumentError
from retrokit.vector import ThreadedVectorEnv, available_cpus

OPTIONS = {"frameskip": 4, "sticky_prob": 0.25, "max_episode_steps": 25, "action_type": "discrete"}


def actions_for(step: int, n: int) -> np.ndarray:
    rng = np.random.default_rng(step)
    return rng.integers(0, 126, n)


@pytest.mark.parametrize("n, threads", [(2, None), (5, 2), (3, 1)], ids=["2-envs", "5-envs-2-threads", "3-envs-1-thread"])
def test_vector_equals_single_envs_through_autoreset(n: int, threads: int | None) -> None:
    seed, steps = 10, 60
    vec = retrokit.make_vec("Airstriker-Genesis", n, threads=threads, **OPTIONS)
    assert vec.threads == min(n, threads or available_cpus())
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


@pytest.mark.parametrize("threads", [0, -1, 1.5], ids=["zero", "negative", "float"])
def test_vector_threads_must_be_a_positive_count(threads: object) -> None:
    with pytest.raises(InvalidArgumentError, match="threads of 1 or more"):
        retrokit.make_vec("Airstriker-Genesis", 2, threads=threads)


def test_vector_needs_at_least_one_env() -> None:
    with pytest.raises(InvalidArgumentError, match="num_envs of 1 or more"):
        retrokit.make_vec("Airstriker-Genesis", 0)


def reference_infos(vec, infos: list[dict]) -> dict:
    """What Gymnasium's own batching makes of the single envs' infos."""
    batched: dict = {}
    for i, info in enumerate(infos):
        batched = gymnasium.vector.VectorEnv._add_info(vec, batched, info, i)
    return batched


@pytest.mark.parametrize("wrapped", [False, True], ids=["native-runner", "python-threads"])
def test_vector_infos_are_batched_as_gymnasium_batches_them(wrapped: bool) -> None:
    n = 3
    make = lambda: retrokit.make("Airstriker-Genesis", **OPTIONS)  # noqa: E731
    fns = [(lambda: gymnasium.wrappers.RecordEpisodeStatistics(make())) if wrapped else make for _ in range(n)]
    vec = ThreadedVectorEnv(fns, threads=2)  # more envs than threads
    assert (vec._runner is None) == wrapped
    singles = [fn() for fn in fns]
    vec.reset(seed=3)
    for i, env in enumerate(singles):
        env.reset(seed=3 + i)
    done = [False] * n
    for step in range(40):
        acts = actions_for(step, n)
        _, _, terms, truncs, infos = vec.step(acts)
        expected = []
        for i, env in enumerate(singles):
            expected.append(env.reset()[1] if done[i] else env.step(acts[i])[4])
            done[i] = bool(terms[i] or truncs[i])
        reference = reference_infos(vec, expected)
        assert infos.keys() == reference.keys()
        for key, value in reference.items():
            if key == "episode":
                continue  # its times differ between the two runs
            assert infos[key].dtype == value.dtype and (infos[key] == value).all(), (step, key)
    vec.close()
    for env in singles:
        env.close()


def test_vector_takes_actions_as_a_list_too() -> None:
    vec = retrokit.make_vec("Airstriker-Genesis", 2, **OPTIONS)
    vec.reset(seed=0)
    from_list = vec.step([5, 7])
    vec.reset(seed=0)
    from_array = vec.step(np.array([5, 7]))
    for a, b in zip(from_list[:4], from_array[:4]):
        assert (a == b).all()
    vec.close()


@pytest.mark.parametrize("mode, kind", [(None, ThreadedVectorEnv), ("sync", gymnasium.vector.SyncVectorEnv)], ids=["default", "sync"])
def test_gymnasium_make_vec_gives_the_threaded_vector_by_default(mode: str | None, kind: type) -> None:
    vec = gymnasium.make_vec("retrokit/Airstriker-Genesis", num_envs=2, vectorization_mode=mode, frameskip=4, max_episode_steps=3)
    assert isinstance(vec, kind) and vec.num_envs == 2
    vec.reset(seed=0)
    for _ in range(3):
        _, _, _, truncated, _ = vec.step(np.zeros((2, 12), dtype=np.int8))
    assert truncated.all()
    vec.close()
