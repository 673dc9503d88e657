"""JERK is the paper's Algorithm 1: its schedule pinned on a tiny deterministic corridor.

The corridor's agent moves one cell a step (LEFT, RIGHT), may hold B, and
earns a point for each cell past its best so far. A scripted random source
makes every draw of JERK's visible, so each test pins a decision to the
paper's rule: jumps of Jn = 4 steps started with Jp = 0.1; Rn = 100 steps
right, then Ln = 70 left when they earned nothing; replays with probability
beta + T/Tmax of the best prefix by mean reward, padded with no-ops.
"""

from __future__ import annotations

import random

import gymnasium
import numpy as np
import pytest
from gymnasium import spaces

from retrokit.benchmark.jerk import BETA, JUMP_PROB, JUMP_REPEAT, LEFT_STEPS, RIGHT_STEPS, Jerk, Solution, jerk
from retrokit.benchmark.monitor import BudgetSpent, Monitor

BUTTONS = ("LEFT", "RIGHT", "B")


class Corridor(gymnasium.Env):
    """A 1-D corridor. Args: wall (a cell it cannot enter), trap (cells past it cost a point), max_steps."""

    def __init__(self, *, wall: int | None = None, trap: int | None = None, max_steps: int = 10_000) -> None:
        self.action_space = spaces.MultiBinary(3)
        self.observation_space = spaces.Box(-10_000, 10_000, (1,), np.int64)
        self.wall, self.trap, self.max_steps = wall, trap, max_steps
        self.log: list[tuple[int, ...]] = []  # every action taken, as a tuple

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.x = self.best = self.steps = 0
        return np.array([self.x]), {}

    def step(self, action):
        left, right, _ = (int(v) for v in action)
        self.log.append(tuple(int(v) for v in action))
        target = self.x + right - left
        if self.wall is None or target != self.wall:
            self.x = target
        reward = max(0, self.x - self.best)
        self.best = max(self.best, self.x)
        if self.trap is not None and self.x > self.trap:
            reward = -1
        self.steps += 1
        return np.array([self.x]), float(reward), False, self.steps >= self.max_steps, {}


def press(names) -> np.ndarray:
    return np.array([int(b in names) for b in BUTTONS], dtype=np.int8)


class Scripted:
    """A random source that plays back given values (then ``rest``), counting its draws."""

    def __init__(self, values: list[float], rest: float = 0.5) -> None:
        self.values, self.rest, self.draws = list(values), rest, 0

    def random(self) -> float:
        self.draws += 1
        return self.values.pop(0) if self.values else self.rest


def play(env: Corridor, budget: int, rng) -> Jerk:
    agent = Jerk(Monitor(env, "corridor", budget, 0, lambda e: None), budget, rng, press=press, jump="B")
    with pytest.raises(BudgetSpent):
        agent.play()
    return agent


def test_the_paper_parameters() -> None:
    assert (BETA, JUMP_REPEAT, JUMP_PROB, RIGHT_STEPS, LEFT_STEPS) == (0.25, 4, 0.1, 100, 70)


def test_a_jump_starts_on_a_draw_below_jp_and_is_held_for_jn_steps() -> None:
    env = Corridor()
    # Step 1 draws 0.5 (no jump), step 2 draws 0.09 (< 0.1: jump), steps 3-5 hold it without drawing,
    # step 6 draws 0.1 (not < 0.1), step 7 draws 0.0 (jump again).
    rng = Scripted([0.5, 0.09, 0.1, 0.0])
    play(env, 12, rng)
    jumped = [a[2] for a in env.log]
    assert jumped == [0, 1, 1, 1, 1, 0, 1, 1, 1, 1, 0, 0]
    assert all(a[:2] == (0, 1) for a in env.log)  # always right: every step gained
    assert rng.draws == 12 - 6 + 1  # none while a jump is held; one for the 13th step, which the budget refused


def test_jump_rate_over_a_long_run_is_jp() -> None:
    env = Corridor()
    play(env, 20_000, random.Random(1))
    jumped = np.array([a[2] for a in env.log]).reshape(-1, RIGHT_STEPS)  # one row per Rn-step move
    held, cut, starts = set(), set(), 0
    for move in jumped:
        edges = np.diff(np.r_[0, move, 0])
        begin, end = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
        starts += len(begin)
        held |= {int(n) % JUMP_REPEAT for n in (end - begin)[end < RIGHT_STEPS]}
        cut |= {int(n) % JUMP_REPEAT for n in (end - begin)[end == RIGHT_STEPS]}
    # A jump is held for Jn steps (back-to-back ones join into runs of 8, 12...), but each move starts with
    # no jump held, as the baselines' move() did, so the last jump of a move may be cut short.
    assert held == {0} and cut > {0}
    assert 0.085 < starts / (jumped.size - jumped.sum() + starts) < 0.115


def test_no_gain_over_rn_steps_backtracks_for_ln_steps() -> None:
    env = Corridor(wall=5, max_steps=400)  # 4 cells of progress, then a wall
    agent = play(env, 400, Scripted([], rest=0.5))
    directions = "".join("L" if a[0] else "R" for a in env.log)
    # 100 right earn 4 points: go on. 100 more earn none: 70 left. Then 100 right regain nothing new: 70 left again.
    assert directions == "R" * 200 + "L" * 70 + "R" * 100 + "L" * 30
    assert agent.events == [("explore", 0), ("backtrack", 200), ("backtrack", 370)]


def test_replays_with_probability_beta_plus_t_over_tmax() -> None:
    env = Corridor(max_steps=10)  # every episode is 10 steps
    # Episode starts at T = 0, 10, 20, ...; the replay threshold is 0.25 + T/100. Each explored episode
    # draws 10 more values (no jump at 0.5). Draws just under the threshold replay, just over explore;
    # from T = 70 on, the 0.5 that follows is under it.
    script = [0.5] * 10 + [0.34, 0.46] + [0.5] * 10 + [0.54, 0.66] + [0.5] * 10 + [0.74, 0.9] + [0.5] * 10
    agent = play(env, 100, Scripted(script))
    assert agent.events == [("explore", 0), ("replay", 10), ("explore", 20), ("replay", 30), ("explore", 40),
                            ("replay", 50), ("explore", 60), ("replay", 70), ("replay", 80), ("replay", 90)]


def test_a_replay_plays_the_best_prefix_then_no_ops_and_joins_its_mean() -> None:
    env = Corridor(trap=6, max_steps=10)  # 6 points, then each step right costs one
    agent = play(env, 20, Scripted([0.5] * 10 + [0.0]))
    assert agent.events == [("explore", 0), ("replay", 10)]
    assert env.log[10:16] == [(0, 1, 0)] * 6 and env.log[16:] == [(0, 0, 0)] * 4
    (solution,) = agent.sequences
    assert len(solution.actions) == 6
    assert solution.rewards == [6.0, 6.0]  # the explored prefix's best, then the replay's total


def test_the_best_sequence_is_the_one_of_highest_mean_reward() -> None:
    agent = Jerk(Corridor(), 10, Scripted([]), press=press, jump="B")
    lucky, steady = Solution(["a"], [10.0, 0.0, 0.0]), Solution(["b"], [6.0])
    agent.sequences = [lucky, steady]
    assert agent.best() is steady
    steady.rewards += [0.0, 0.0]  # its mean falls to 2, below lucky's 3.33
    assert agent.best() is lucky


def test_ties_go_to_the_later_sequence_as_the_baselines_sorted_them() -> None:
    agent = Jerk(Corridor(), 10, Scripted([]), press=press, jump="B")
    first, second = Solution(["a"], [5.0]), Solution(["b"], [5.0])
    agent.sequences = [first, second]
    assert agent.best() is second


def test_jerk_spends_exactly_its_budget() -> None:
    env = Corridor(wall=30, max_steps=300)
    monitor = Monitor(env, "corridor", 1234, 0, lambda e: None)
    with pytest.raises(BudgetSpent):
        Jerk(monitor, 1234, random.Random(0), press=press, jump="B").play()
    assert monitor.timesteps == len(env.log) == 1234


def test_jerk_needs_buttons_it_can_press_by_name() -> None:
    from retrokit.errors import InvalidArgumentError

    with pytest.raises(InvalidArgumentError, match="press by name"):
        jerk(Corridor(), 10, 0)
