"""The evaluator at the env's speed: the monitor checks each distinct action once, workers take the next level as
soon as they are free, and a run ends with the Sonic protocol's time at its speed."""

from __future__ import annotations

import json

import gymnasium
import pytest
from evaluating import write_agents

from retrokit.benchmark.agents import random_agent
from retrokit.benchmark.definition import load_benchmark
from retrokit.benchmark.jerk import jerk
from retrokit.benchmark.monitor import BudgetSpent, Monitor
from retrokit.benchmark.speed import (
    SONIC_BUDGET,
    SONIC_LEVELS,
    Speed,
    busy_workers,
    estimate_line,
    protocol_minutes,
)
from retrokit.cli import main
from retrokit.envs.env import RetroEnv
from retrokit.errors import AgentError


@pytest.fixture
def dasher_level():
    benchmark = load_benchmark("dasher")
    options = benchmark.env_options()
    env = RetroEnv("Dasher-Genesis", "Zone2.Act2", options.pop("scenario", None), **options)
    yield env
    env.close()


@pytest.fixture
def counted_checks(monkeypatch) -> list[object]:
    """Every action the action space's check is asked about."""
    asked: list[object] = []
    contains = gymnasium.spaces.MultiBinary.contains

    def counting(space, x) -> bool:
        asked.append(x)
        return contains(space, x)

    monkeypatch.setattr(gymnasium.spaces.MultiBinary, "contains", counting)
    return asked


@pytest.mark.parametrize("agent", [jerk, random_agent], ids=["jerk", "random"])
def test_the_monitor_checks_each_distinct_action_once(dasher_level, counted_checks, agent) -> None:
    monitor = Monitor(dasher_level, "Dasher-Genesis/Zone2.Act2", 300, 0, lambda e: None)
    with pytest.raises(BudgetSpent):
        agent(monitor, 300, 0)
    assert monitor.timesteps == 300
    distinct = {bytes(x) for x in counted_checks}
    # JERK presses 5 actions; 300 random draws among 4096 repeat some (all distinct: a chance of 1 in 50,000)
    assert len(counted_checks) == len(distinct) < 300


def test_an_action_changed_in_place_is_checked_again(dasher_level) -> None:
    monitor = Monitor(dasher_level, "Dasher-Genesis/Zone2.Act2", 100, 0, lambda e: None)
    monitor.reset()
    action = dasher_level.actions.press(["RIGHT"])
    monitor.step(action)
    monitor.step(action)
    action[0] = 2  # the agent reuses its array with a value out of range
    with pytest.raises(AgentError, match=r"Expected an action of MultiBinary\(12\) \(level Dasher-Genesis/Zone2.Act2, step 3\)"):
        monitor.step(action)
    with pytest.raises(AgentError, match="step 3"):
        monitor.step([0] * 5)  # a list, checked every time


TIMED_AGENT = '''
import json, os, pathlib, time
import gymnasium
from retrokit.benchmark.jerk import jerk

HERE = pathlib.Path(__file__).parent

class Slow(gymnasium.Wrapper):
    """When the test asks for it, the first step waits until the last level has begun (up to 5 minutes).

    So this level is still playing when the last one begins, however fast or slow the machine is.
    """

    waited = False

    def step(self, action):
        deadline = time.monotonic() + 300
        while not self.waited and (HERE / "slow").exists() and not (HERE / "Zone3.Act2.began").exists():
            if time.monotonic() > deadline:
                break  # the test's assertions then say which level began late
            time.sleep(0.05)
        self.waited = True
        return self.env.step(action)

def timed_jerk(env, budget, seed):
    """JERK, slow on Zone1.Act2, noting when each level's play began and ended, and in which process."""
    level, began = env.unwrapped.state_name, time.time()
    (HERE / f"{level}.began").touch()
    try:
        jerk(Slow(env) if level == "Zone1.Act2" else env, budget, seed)
    finally:
        with open(HERE / "times.jsonl", "a") as log:
            log.write(json.dumps({"level": level, "pid": os.getpid(), "began": began, "ended": time.time()}) + "\\n")
'''


def test_a_free_worker_takes_the_next_level_while_a_long_one_plays(tmp_path, capsys) -> None:
    agent = write_agents(tmp_path, TIMED_AGENT)
    args = ["evaluate", "--benchmark", "dasher", "--levels", "Zone1.Act2,Zone2.Act2,Zone3.Act2", "--timesteps", "100",
            "--agent", f"{agent}:timed_jerk", "--no-progress"]
    assert main([*args, "--workers", "1", "--out", str(tmp_path / "one")]) == 0
    for mark in [tmp_path / "times.jsonl", *tmp_path.glob("*.began")]:
        mark.unlink()
    (tmp_path / "slow").touch()  # Zone1.Act2 waits at its first step until Zone3.Act2 begins
    assert main([*args, "--workers", "2", "--out", str(tmp_path / "two")]) == 0
    times = {t["level"]: t for t in map(json.loads, (tmp_path / "times.jsonl").read_text().splitlines())}
    long, short, last = times["Zone1.Act2"], times["Zone2.Act2"], times["Zone3.Act2"]
    assert long["began"] < short["ended"]  # both workers busy from the start
    assert short["ended"] <= last["began"] < long["ended"]  # the free worker took the last level at once
    assert len({t["pid"] for t in times.values()}) == 3  # each level in a process of its own
    assert (tmp_path / "one" / "summary.json").read_bytes() == (tmp_path / "two" / "summary.json").read_bytes()
    last_line = capsys.readouterr().err.strip().splitlines()[-1]  # after the results, with the progress
    assert last_line.startswith("speed: ") and last_line.endswith("with 2 level(s) at once.")
    assert "Sonic" not in last_line  # the protocol's time is the Sonic benchmark's alone


def test_the_protocol_is_the_papers() -> None:
    sonic = load_benchmark("sonic")
    assert (SONIC_LEVELS, SONIC_BUDGET) == (len(sonic.test), sonic.budget) == (11, 1_000_000)


def test_the_protocol_takes_its_rounds_of_levels_at_the_level_speed() -> None:
    assert protocol_minutes(1000.0, 2, 2) == pytest.approx(6 * 1000 / 60)  # 11 levels on 2 workers: 6 rounds
    assert protocol_minutes(1000.0, 11, 11) == pytest.approx(1000 / 60)
    # More levels than cores share them: 11 at once on 2 cores, or rounds of 3, 3, 3 and 2, keep both busy.
    assert protocol_minutes(1000.0, 11, 2) == pytest.approx(5.5 * 1000 / 60)
    assert protocol_minutes(1000.0, 3, 2) == pytest.approx((3 * 1.5 + 1) * 1000 / 60)
    line = estimate_line(Speed(steps=20_000, seconds=20.0, workers=4, at_once=2, cores=4))
    assert "1,000 env steps/s per level, 2,000 in all with 2 level(s) at once" in line
    assert "about 50 minutes here with --workers 4 (3 round(s) of levels)" in line
    assert "measured with 2 level(s) at once, so with 4 at once it may be slower" in line
    alone = estimate_line(Speed(steps=20_000, seconds=20.0, workers=4, at_once=2, cores=4), sonic=False)
    assert alone == "speed: 1,000 env steps/s per level, 2,000 in all with 2 level(s) at once."


def test_a_level_rate_measured_with_the_cores_shared_is_a_cores_rate_shared() -> None:
    shared = Speed(steps=20_000, seconds=30.0, workers=3, at_once=3, cores=2)  # 3 levels on 2 cores
    assert shared.core_rate == pytest.approx(1000.0)
    assert estimate_line(shared).endswith("--workers 3 (4 round(s) of levels).")  # every round busies both cores


@pytest.mark.parametrize(
    "cores, workers", [(1, 1), (2, 3), (3, 4), (4, 6), (6, 11), (16, 11)], ids=lambda v: str(v)
)
def test_the_busy_worker_count_leaves_no_core_idle_in_the_last_round(cores: int, workers: int) -> None:
    assert busy_workers(cores) == workers
    last = SONIC_LEVELS % workers or workers
    assert last >= min(cores, SONIC_LEVELS)


def test_a_last_round_that_leaves_cores_idle_names_the_worker_count_that_does_not() -> None:
    line = estimate_line(Speed(steps=20_000, seconds=20.0, workers=2, at_once=2, cores=2))
    assert "about 100 minutes here with --workers 2 (6 round(s) of levels)" in line
    assert line.endswith(
        "its last round plays 1 level(s) on 2 cores, leaving 1 idle: --workers 3 keeps every core busy in every "
        "round, about 92 minutes."
    )