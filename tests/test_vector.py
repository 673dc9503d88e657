"""The threaded vector env gives exactly what N single envs give."""

from __future__ import annotations

import hashlib
from collections.abc import Callable

import gymnasium
import numpy as np
import pytest

import retrokit
from retrokit.envs.vector import ThreadedVectorEnv, available_cpus
from retrokit.errors import InvalidArgumentError

OPTIONS = {"frameskip": 4, "sticky_prob": 0.25, "max_episode_steps": 25, "action_type": "discrete"}


def actions_for(step: int, n: int) -> np.ndarray:
    rng = np.random.default_rng(step)
    return rng.integers(0, 126, n)


# Ends an episode on the second frame of a step, so per-frame envs stop mid-step.
MID_STEP = {"reward": "delta(score)", "done": "frame >= 37 or gameover == 1"}


# Steps compared: the 25-step limit ends every episode once (the next step autoresets) and ten steps follow.
STEPS, MOST_ENVS = 35, 5


def pixels(obs: np.ndarray) -> str:
    """An observation's digest: equal digests, equal pixels."""
    return hashlib.sha1(obs.tobytes()).hexdigest()


def trace(obs: np.ndarray, reward: float, terminated: bool, truncated: bool, info: dict) -> tuple:
    """One env's step as compared."""
    return pixels(obs), reward, terminated, truncated, info["score"], info["lives"]


@pytest.fixture(scope="module")
def single_runs() -> Callable[[bool], list[list[tuple]]]:
    """Single envs 0..MOST_ENVS-1 stepped as the vector steps them, through their autoresets; made once per
    scenario mode for every vector size (env i's run does not depend on how many envs the vector has)."""
    runs: dict[bool, list[list[tuple]]] = {}

    def get(every_frame: bool) -> list[list[tuple]]:
        if every_frame not in runs:
            runs[every_frame] = []
            for i in range(MOST_ENVS):
                env = retrokit.make("Airstriker-Genesis", **vector_options(every_frame))
                steps, done = [(pixels(env.reset(seed=SEED + i)[0]),)], False
                for step in range(STEPS):
                    if done:  # next-step autoreset: this step resets, reward 0
                        obs, info = env.reset()
                        steps.append(trace(obs, 0.0, False, False, info))
                    else:
                        steps.append(trace(*env.step(actions_for(step, MOST_ENVS)[i])))
                    done = steps[-1][2] or steps[-1][3]
                runs[every_frame].append(steps)
                env.close()
        return runs[every_frame]

    return get


SEED = 10


def vector_options(every_frame: bool) -> dict:
    return {**OPTIONS, "scenario_every_frame": every_frame, "scenario": MID_STEP if every_frame else None}


@pytest.mark.parametrize("every_frame", [False, True], ids=["per-step", "per-frame"])
@pytest.mark.parametrize("n, threads", [(2, None), (5, 2), (3, 1)], ids=["2-envs", "5-envs-2-threads", "3-envs-1-thread"])
def test_vector_equals_single_envs_through_autoreset(
    single_runs: Callable[[bool], list[list[tuple]]], n: int, threads: int | None, every_frame: bool
) -> None:
    vec = retrokit.make_vec("Airstriker-Genesis", n, threads=threads, **vector_options(every_frame))
    assert vec.threads == min(n, threads or available_cpus())
    assert vec.native  # both kinds run on the native runner
    singles = single_runs(every_frame)[:n]
    obs, infos = vec.reset(seed=SEED)
    assert all((pixels(obs[i]),) == singles[i][0] for i in range(n))
    resets = 0
    for step in range(STEPS):
        acts = actions_for(step, MOST_ENVS)[:n]
        obs, rewards, terms, truncs, infos = vec.step(acts)
        for i, single in enumerate(singles):
            got = trace(obs[i], rewards[i], terms[i], truncs[i], {key: infos[key][i] for key in ("score", "lives")})
            assert got == single[step + 1], f"env {i} of {n}, step {step}: vector {got}, single env {single[step + 1]}"
            resets += step > 0 and bool(single[step][2] or single[step][3])  # this step autoreset
    assert resets >= n  # the 25-step limit forced autoresets along the way
    vec.close()


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
    with pytest.raises(InvalidArgumentError, match="num_envs from 1 to"):
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
    make = lambda: retrokit.make("Airstriker-Genesis", **OPTIONS)
    fns = [(lambda: gymnasium.wrappers.RecordEpisodeStatistics(make())) if wrapped else make for _ in range(n)]
    vec = ThreadedVectorEnv(fns, threads=2)  # more envs than threads
    assert vec.native != wrapped
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
    vec = gymnasium.make_vec("retrokit/Airstriker-Genesis-v0", num_envs=2, vectorization_mode=mode, frameskip=4, max_episode_steps=3)
    assert isinstance(vec, kind) and vec.num_envs == 2
    vec.reset(seed=0)
    for _ in range(3):
        _, _, _, truncated, _ = vec.step(np.zeros((2, 12), dtype=np.int8))
    assert truncated.all()
    vec.close()


@pytest.mark.parametrize("every_frame", [False, True], ids=["per-step", "per-frame"])
def test_vector_movies_replay_what_each_env_saw(tmp_path, every_frame: bool) -> None:
    from retrokit.movie import play

    theirs = tmp_path / "Dasher-Genesis-Zone1.Act1-000000.bk2"
    theirs.write_bytes(b"a file the user made")
    vec = retrokit.make_vec(
        "Dasher-Genesis", 2, frameskip=4, sticky_prob=0.5, max_episode_steps=12, record=tmp_path,
        action_type="all", scenario_every_frame=every_frame,
    )
    vec.reset(seed=0)
    rng = np.random.default_rng(1)
    seen = []  # (movie, index of the step's last frame in it, what the env saw)
    frames_in: dict = {}
    for _ in range(30):
        movies = [env.movies.recorder.path if env.movies.recorder is not None else None for env in vec.envs]
        before = [env.emulator.frame for env in vec.envs]
        obs = vec.step((rng.random((2, 12)) < 0.3).astype(np.int8))[0]
        for i, env in enumerate(vec.envs):
            if movies[i] is None:
                continue  # this step reset the env
            frames_in[movies[i]] = frames_in.get(movies[i], 0) + env.emulator.frame - before[i]
            seen.append((movies[i], frames_in[movies[i]] - 1, obs[i].copy()))
    vec.close()
    assert theirs.read_bytes() == b"a file the user made"
    written = sorted(p for p in tmp_path.glob("*.bk2") if p != theirs)
    assert set(written) == set(frames_in) and len(written) >= 4  # both envs, two episodes or more each
    replays = {movie: list(play(movie)) for movie in written}
    assert all(len(replays[movie]) == count for movie, count in frames_in.items())
    assert all((replays[movie][index] == frame).all() for movie, index, frame in seen)


class CountingEnv(retrokit.RetroEnv):
    """A user's subclass whose step does more than RetroEnv's."""

    def step(self, action):
        self.counted = getattr(self, "counted", 0) + 1
        return super().step(action)


def test_a_subclass_that_overrides_step_is_stepped_through_its_own_step() -> None:
    vec = ThreadedVectorEnv([lambda: CountingEnv("Airstriker-Genesis", **OPTIONS)] * 2)
    plain = retrokit.make("Airstriker-Genesis", **OPTIONS)
    assert plain.stepping is not None and vec.envs[0].stepping is None
    assert not vec.native  # the native runner would bypass the override
    vec.reset(seed=0)
    for step in range(3):
        vec.step(actions_for(step, 2))
    assert [env.counted for env in vec.envs] == [3, 3]
    vec.close()
    plain.close()
