"""make_vec's num_envs and the vector step's actions: hostile values end in InvalidArgumentError, never a raw one."""

from __future__ import annotations

from contextlib import closing

import numpy as np
import pytest
from childproc import MAX_RSS_MB, run_child

import retrokit
from retrokit.envs import memory, vector
from retrokit.errors import InvalidArgumentError


@pytest.mark.parametrize(
    ("num_envs", "found"),
    [(2.5, "got 2.5 (float)"), ("2", "got '2' (str)"), (True, "got True (bool)"), (None, "got None"), (0, "got 0")],
    ids=["float", "str", "bool", "none", "zero"],
)
def test_num_envs_must_be_a_whole_number_from_1(num_envs: object, found: str) -> None:
    with pytest.raises(InvalidArgumentError, match="num_envs") as caught:
        retrokit.make_vec("Airstriker-Genesis", num_envs)
    assert found in str(caught.value)


def test_num_envs_may_be_a_numpy_integer() -> None:
    with closing(retrokit.make_vec("Airstriker-Genesis", np.int64(2))) as vec:
        assert vec.num_envs == 2


def test_a_million_envs_are_refused_at_once_without_building_any() -> None:
    child = run_child(
        """
        import time, retrokit
        from retrokit.errors import InvalidArgumentError
        start = time.process_time()  # its own CPU: the waits of a loaded machine do not count
        try:
            retrokit.make_vec("Airstriker-Genesis", 10**6)
        except InvalidArgumentError as exc:
            print("refused", round(time.process_time() - start, 3), exc)
        """,
        timeout=60,
    )
    assert child.returncode == 0 and child.stdout.startswith("refused"), child.describe()
    assert float(child.stdout.split()[1]) < 1 and "each takes at least 1 MiB" in child.stdout
    assert child.peak_rss_mb < MAX_RSS_MB


def test_a_count_over_the_address_space_limit_is_refused_after_two_envs() -> None:
    # The child runs under a 3 GiB address-space limit (childproc): 300 envs of about 20 MiB each do not fit.
    child = run_child(
        """
        import retrokit
        from retrokit.envs import env as env_module
        from retrokit.errors import InvalidArgumentError
        built = []
        make = env_module.make
        env_module.make = lambda *a, **k: built.append(1) or make(*a, **k)  # count what is built
        try:
            retrokit.make_vec("Airstriker-Genesis", 300)
        except InvalidArgumentError as exc:
            print("refused after", len(built), exc)
        """,
        timeout=120,
    )
    assert child.returncode == 0 and child.stdout.startswith("refused after 2 "), child.describe()
    assert "each takes about" in child.stdout and "ulimit -v" in child.stdout, child.stdout
    assert child.peak_rss_mb < MAX_RSS_MB


def test_a_count_over_the_memory_available_is_refused_after_two_envs(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(memory, "available_memory", lambda: 64 * 2**20)  # a small machine's 64 MiB
    with pytest.raises(InvalidArgumentError, match=r"each takes about .* found 64 MiB of memory available") as caught:
        retrokit.make_vec("Airstriker-Genesis", 20)
    assert "Pass a num_envs of at most " in str(caught.value)
    with closing(retrokit.make_vec("Airstriker-Genesis", 3)) as vec:  # a count that fits is built
        assert vec.num_envs == 3


@pytest.fixture(scope="module")
def vec():
    with closing(retrokit.make_vec("Airstriker-Genesis", 2)) as env:
        env.reset(seed=0)
        yield env


@pytest.mark.parametrize(
    ("actions", "found"),
    [
        (np.zeros((3, 12), np.int8), "found 3."),
        (np.zeros((1, 12), np.int8), "found 1."),
        ([np.zeros(12, np.int8)] * 3, "found 3."),
        ([np.zeros(12, np.int8)], "found 1."),
        (5, "found 5, which is not a batch"),
        (None, "found None, which is not a batch"),
    ],
    ids=["array-of-3", "array-of-1", "list-of-3", "list-of-1", "a-number", "none"],
)
def test_a_step_needs_one_action_per_env(vec, actions: object, found: str) -> None:
    with pytest.raises(InvalidArgumentError, match=r"Expected 2 actions \(one per env, e\.g\. an array of shape \(2, 12\)\)") as caught:
        vec.step(actions)
    assert found in str(caught.value)


def test_a_step_takes_a_list_or_an_array_of_one_action_each(vec) -> None:
    for actions in ([np.zeros(12, np.int8)] * 2, np.zeros((2, 12), np.int8)):
        observations, rewards, *_ = vec.step(actions)
        assert len(observations) == len(rewards) == 2


def test_an_array_of_num_envs_rows_is_stepped_without_iterating(vec, monkeypatch: pytest.MonkeyPatch) -> None:
    # The usual batch (an array of one row per env) takes the fast path: no iteration, no per-step check.
    def refuse(*args, **kwargs):
        raise AssertionError("the fast path iterated the actions")

    monkeypatch.setattr(vector, "iterate", refuse)
    observations, rewards, *_ = vec.step(np.zeros((2, 12), np.int8))
    assert len(observations) == len(rewards) == 2
