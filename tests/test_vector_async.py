"""The vector env's asynchronous mode: send(actions, env_ids) then recv(), on Airstriker."""

from __future__ import annotations

import functools

import gymnasium
import numpy as np
import pytest

import retrokit
from retrokit.envs.vector import ThreadedVectorEnv
from retrokit.errors import EnvError, InvalidArgumentError

GAME = "Airstriker-Genesis"
# Short episodes, so that autoresets happen within a few steps.
OPTIONS = {"frameskip": 4, "sticky_prob": 0.25, "max_episode_steps": 7, "action_type": "discrete"}


def actions_for(step: int, n: int) -> np.ndarray:
    return np.random.default_rng(step).integers(0, 126, n)


def assert_same_step(got: tuple, k: int, expected: tuple, where: object) -> None:
    """Row k of a recv's batch is the step ``expected`` (a single env's 5-tuple)."""
    obs, rewards, terms, truncs, infos = got[:5]
    assert (obs[k] == expected[0]).all(), where
    assert (rewards[k], terms[k], truncs[k]) == (expected[1], expected[2], expected[3]), where
    for key in ("score", "lives", "gameover"):
        assert infos[key][k] == expected[4][key] and infos[f"_{key}"][k], (where, key)


@pytest.mark.parametrize("batch_size", [None, 1, 2], ids=["whole-batches", "one-at-a-time", "batches-of-2"])
def test_async_gives_the_sync_trajectories_through_autoreset(batch_size: int | None) -> None:
    """Same seeds, same actions: every env's steps through send/recv are those of the sync step."""
    n, seed, steps = 3, 5, 20
    sync = retrokit.make_vec(GAME, n, **OPTIONS)
    vec = retrokit.make_vec(GAME, n, batch_size=batch_size, **OPTIONS)
    assert vec.batch_size == (batch_size or n)
    sync_obs, _ = sync.reset(seed=seed)
    obs, _ = vec.reset(seed=seed)
    assert (obs == sync_obs).all()
    expected = [sync.step(actions_for(step, n)) for step in range(steps)]
    autoresets = 0
    for step in range(steps):
        vec.send(actions_for(step, n))
        seen: list[int] = []
        while len(seen) < n:
            got = vec.recv()
            assert 1 <= len(got[5]) <= vec.batch_size
            for k, env_id in enumerate(got[5]):
                want = tuple(part[env_id] for part in expected[step][:4]) + (
                    {key: expected[step][4][key][env_id] for key in ("score", "lives", "gameover")},
                )
                assert_same_step(got, k, want, (step, env_id))
                autoresets += step > 0 and bool(expected[step - 1][3][env_id]) and got[1][k] == 0.0
            seen += list(got[5])
        assert sorted(seen) == list(range(n))
    assert autoresets >= n  # every env's 7-step episodes ended and were reset along the way
    vec.close()
    sync.close()


def test_env_ids_step_only_those_envs_and_autoreset_per_env() -> None:
    """Subsets step independently; the send after an env's last step resets it (reward 0, its first frame)."""
    n = 3
    vec = retrokit.make_vec(GAME, n, **{**OPTIONS, "max_episode_steps": 2})
    singles = [retrokit.make(GAME, **{**OPTIONS, "max_episode_steps": 2}) for _ in range(n)]
    vec.reset(seed=0)
    for i, env in enumerate(singles):
        env.reset(seed=i)
    plan = [[2], [0, 2], [2], [1], [2, 1, 0], [0]]  # env 2 ends its episode at its 2nd step, resets at its 3rd
    ended, resets = [False] * n, []
    for t, ids in enumerate(plan):
        actions = actions_for(t, len(ids))
        vec.send(actions, env_ids=ids)
        got = vec.recv()
        assert sorted(got[5]) == sorted(ids)
        order = {env_id: k for k, env_id in enumerate(got[5])}
        for action, env_id in zip(actions, ids):
            env = singles[env_id]
            if ended[env_id]:  # next-step autoreset, as the vector env does it
                first, info = env.reset()
                expected = (first, 0.0, False, False, info)
                resets.append((t, env_id))
            else:
                expected = env.step(action)
            ended[env_id] = expected[2] or expected[3]
            assert_same_step(got, order[env_id], expected, (t, env_id))
    assert resets == [(2, 2), (5, 0)]  # each env reset after its own 2nd step, whatever the others did
    vec.close()
    for env in singles:
        env.close()


def test_recv_returns_the_first_done_and_keeps_the_rest_in_flight() -> None:
    vec = retrokit.make_vec(GAME, 4, batch_size=3, **OPTIONS)
    vec.reset(seed=1)
    vec.send(np.zeros(4, dtype=np.int64))
    assert vec.in_flight == 4
    first = vec.recv()
    assert len(first[5]) == 3 and first[0].shape == (3, 224, 320, 3)
    assert vec.in_flight == 1
    with pytest.raises(EnvError, match="in flight"):
        vec.send(np.zeros(4, dtype=np.int64))  # one is still out
    rest = vec.recv()  # fewer than batch_size left: all of them
    assert vec.in_flight == 0
    assert sorted([*first[5], *rest[5]]) == [0, 1, 2, 3]
    vec.send(np.zeros(4, dtype=np.int64))  # everything came back: all may go again
    again = vec.recv()[5]
    assert len(again) == 3 and set(again) < {0, 1, 2, 3}
    vec.close()


def test_recv_before_send_is_a_clear_error() -> None:
    vec = retrokit.make_vec(GAME, 2, **OPTIONS)
    vec.reset(seed=0)
    with pytest.raises(EnvError, match=r"Expected a send\(\) before recv\(\)"):
        vec.recv()
    vec.send([1, 2])
    vec.recv()
    with pytest.raises(EnvError, match="no env is in flight"):
        vec.recv()  # everything sent came back
    vec.close()


@pytest.mark.parametrize(
    "env_ids, match",
    [
        ([0, 2], "from 0 to 1"),
        ([-1], "from 0 to 1"),
        ([0, 0], r"at most once in a send; found \[0\]"),
        ([0.5], "whole numbers"),
        ([True], "whole numbers"),
        ("01", "sequence of env indices"),
        ([[0], [1]], "sequence of env indices"),
        ([], "at least one env id"),
    ],
    ids=["out-of-range", "negative", "duplicated", "float", "bool", "string", "nested", "empty"],
)
def test_send_refuses_wrong_env_ids(env_ids: object, match: str) -> None:
    vec = retrokit.make_vec(GAME, 2, **OPTIONS)
    vec.reset(seed=0)
    with pytest.raises(InvalidArgumentError, match=match):
        vec.send(np.zeros(max(len(env_ids), 1), dtype=np.int64), env_ids=env_ids)
    vec.send([3, 4])  # a refused send leaves nothing in flight
    assert sorted(vec.recv()[5]) == [0, 1]
    vec.close()


def test_a_huge_list_of_repeated_ids_is_refused_at_once() -> None:
    vec = retrokit.make_vec(GAME, 2, **OPTIONS)
    with pytest.raises(InvalidArgumentError, match="at most 2; found 400000 ids"):
        vec.send(np.zeros(400_000, dtype=np.int64), env_ids=[0, 1] * 200_000)  # no quadratic count: no hang
    vec.close()


def test_send_refuses_actions_that_do_not_match_the_ids() -> None:
    vec = retrokit.make_vec(GAME, 3, **OPTIONS)
    vec.reset(seed=0)
    with pytest.raises(InvalidArgumentError, match="Expected 2 actions"):
        vec.send([1, 2, 3], env_ids=[0, 1])
    with pytest.raises(InvalidArgumentError, match="not a batch"):
        vec.send(None)
    vec.close()


def test_sending_twice_or_stepping_while_in_flight_is_a_clear_error() -> None:
    vec = retrokit.make_vec(GAME, 2, **OPTIONS)
    vec.reset(seed=0)
    vec.send([1], env_ids=[1])
    with pytest.raises(EnvError, match=r"envs \[1\] were sent and not yet received"):
        vec.send([1, 2])
    vec.send([1], env_ids=[0])  # another env may go meanwhile
    with pytest.raises(EnvError, match=r"no env in flight at step\(\)"):
        vec.step([1, 2])
    with pytest.raises(EnvError, match=r"no env in flight at reset\(\)"):
        vec.reset()
    ids = [*vec.recv()[5]]
    ids += [*vec.recv()[5]] if len(ids) < 2 else []
    assert sorted(ids) == [0, 1]
    vec.step([1, 2])  # all back: the sync step works again
    vec.close()


@pytest.mark.parametrize("batch_size", [0, 3, 1.5, True], ids=["zero", "over-num-envs", "float", "bool"])
def test_batch_size_is_checked(batch_size: object) -> None:
    with pytest.raises(InvalidArgumentError, match="batch_size from 1 to 2"):
        retrokit.make_vec(GAME, 2, batch_size=batch_size, **OPTIONS)


class FailsAtStep(gymnasium.Wrapper):
    """An env whose step fails after ``after`` steps, as a user's wrapper might."""

    def __init__(self, env: gymnasium.Env, after: int) -> None:
        super().__init__(env)
        self.after = after

    def step(self, action):
        self.after -= 1
        if self.after < 0:
            raise InvalidArgumentError("Expected a good action; found a bad one. (a test's wrapper)")
        return self.env.step(action)


def failing_env(after: int) -> gymnasium.Env:
    return FailsAtStep(retrokit.make(GAME, **OPTIONS), after)


def test_a_failing_step_is_raised_by_recv_and_leaves_the_env_usable() -> None:
    vec = ThreadedVectorEnv([functools.partial(failing_env, 100), functools.partial(failing_env, 0)])
    assert not vec.native  # wrapped envs step on Python threads, async too
    vec.reset(seed=0)
    vec.send([1, 2])
    with pytest.raises(InvalidArgumentError, match="a test's wrapper"):
        vec.recv()
    assert vec.in_flight == 1  # the failed env is no longer in flight; the one beside it stepped, and waits
    assert list(vec.recv()[5]) == [0]
    vec.send([1], env_ids=[0])
    assert list(vec.recv()[5]) == [0]
    vec.close()


def test_close_with_envs_in_flight_waits_for_them() -> None:
    vec = retrokit.make_vec(GAME, 2, **OPTIONS)
    vec.reset(seed=0)
    vec.send([1, 2])
    vec.close()  # the steps in flight finish before the emulators close: no crash, no hang
    assert vec.in_flight == 0


TWO_THREADS = """
import threading
import numpy as np
import retrokit
from retrokit.errors import EnvError

vec = retrokit.make_vec("Airstriker-Genesis", 4, frameskip=1, action_type="discrete")
vec.reset(seed=0)
wrong = []

def drive(ids):
    for _ in range(400):
        vec.send(np.zeros(len(ids), dtype=np.int64), env_ids=ids)
        got = []
        while len(got) < len(ids):
            got += list(vec.recv()[5])
        if sorted(got) != ids:
            wrong.append((ids, got))

threads = [threading.Thread(target=drive, args=(ids,)) for ids in ([0, 1], [2, 3])]
for t in threads:
    t.start()
for t in threads:
    t.join()
assert not wrong, wrong[:3]
vec.send([0], env_ids=[0])
outside = []
side = threading.Thread(target=lambda: outside.append(pytest_raises(vec.recv)))
def pytest_raises(call):
    try:
        call()
    except EnvError as exc:
        return str(exc)
side.start()
side.join()
assert "sent by another thread" in outside[0], outside
assert list(vec.recv()[5]) == [0]
vec.close()
print("both threads got their own envs, 400 rounds each")
"""


def test_two_threads_each_receive_the_envs_they_sent() -> None:
    """Two threads drive their own envs of one vector env: neither takes the other's results, neither hangs."""
    from childproc import run_child

    child = run_child(TWO_THREADS, timeout=300)
    assert child.returncode == 0 and "400 rounds each" in child.stdout, child.describe()


def test_one_bad_action_loses_none_of_the_other_envs_steps() -> None:
    vec = retrokit.make_vec(GAME, 4, **OPTIONS)
    vec.reset(seed=0)
    vec.send([1, 2, 10_000, 3])
    with pytest.raises(InvalidArgumentError) as raised:
        vec.recv()
    assert vec.in_flight == 3
    rest = vec.recv()
    assert sorted(rest[5]) == [0, 1, 3] and rest[0].shape[0] == 3 and vec.in_flight == 0
    assert any("next recv() returns them" in note for note in raised.value.__notes__)
    vec.close()
