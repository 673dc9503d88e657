"""JERK ("Just Enough Retained Knowledge"), the paper's Algorithm 1.

From "Gotta Learn Fast" (Nichol et al., 2018), with its parameters β = 0.25,
Jn = 4, Jp = 0.1, Rn = 100 and Ln = 70. At the start of each episode, once it
has sequences, JERK replays the best one with probability β + T/Tmax (T the
timesteps spent so far, Tmax the budget): the sequence with the highest mean
episode reward, padded with no-ops until the episode ends, and the replay's
reward joins that mean. Otherwise it explores: it runs right for Rn steps,
jumping for Jn steps with probability Jp at each step it is not jumping, and
when the reward did not increase over those Rn steps it runs left for Ln
steps, jumping the same way; until the episode ends. It jumps with the
game's jump button (the scenario's ``jump``, else the system's descriptor's:
``B`` on a Genesis, ``A`` on a NES, ``BUTTON`` on an Atari 2600), through any
of the env's action types. The explored episode's
prefix up to its best cumulative reward becomes a new sequence, whose mean
starts at that best cumulative reward.

The order of the random draws follows the baselines' published agent, so a
seed picks the same decisions.
"""

from __future__ import annotations

import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import gymnasium

from retrokit.errors import InvalidArgumentError

BETA = 0.25  #: the initial exploitation fraction
JUMP_REPEAT = 4  #: Jn: steps a jump is held
JUMP_PROB = 0.1  #: Jp: probability of starting a jump
RIGHT_STEPS = 100  #: Rn: steps of exploration between checks of the reward
LEFT_STEPS = 70  #: Ln: steps of backtracking


@dataclass
class Solution:
    """An action sequence JERK keeps, and the rewards it earned (their mean ranks it)."""

    actions: list[Any]
    rewards: list[float] = field(default_factory=list)

    @property
    def mean(self) -> float:
        """The running mean of its rewards."""
        return sum(self.rewards) / len(self.rewards)


class Jerk:
    """The JERK agent on one level.

    Args:
        env: The level's env (its ``step`` raises when the budget is spent).
        budget: Tmax, the timesteps of the level.
        rng: Its randomness: anything with ``random()`` giving floats in [0, 1).
        press: Returns the action pressing some named buttons (``press(["RIGHT", "B"])``);
            by default the env's own, ``env.unwrapped.actions.press``, which works
            with every action type of a retrokit env. Give one to run JERK on
            another env whose actions are not retrokit's.
        jump: The button that jumps; by default the env's ``jump_button``: the
            scenario's ``jump``, else the system's (``retrokit/host/systems.yaml``).
        beta, jump_repeat, jump_prob, right_steps, left_steps: The paper's parameters.
    """

    def __init__(
        self,
        env: gymnasium.Env,
        budget: int,
        rng: Any,
        *,
        press: Callable[[Sequence[str]], Any] | None = None,
        jump: str | None = None,
        beta: float = BETA,
        jump_repeat: int = JUMP_REPEAT,
        jump_prob: float = JUMP_PROB,
        right_steps: int = RIGHT_STEPS,
        left_steps: int = LEFT_STEPS,
    ) -> None:
        if press is None:
            press = getattr(getattr(env.unwrapped, "actions", None), "press", None)
            if press is None:
                raise InvalidArgumentError(
                    f"Expected an env whose buttons JERK can press by name (a retrokit env), got {env.unwrapped!r}; "
                    "pass press=, a function from button names to the env's action, to Jerk."
                )
        jump = jump or getattr(env.unwrapped, "jump_button", None)
        if not jump:
            raise InvalidArgumentError(
                f"Expected a button for JERK to jump with, but {env.unwrapped!r} names none; pass jump= to Jerk, "
                "or name one in the scenario (jump: A) or the system's descriptor."
            )
        self.env, self.budget, self.rng = env, budget, rng
        self.beta, self.jump_repeat, self.jump_prob = beta, jump_repeat, jump_prob
        self.right_steps, self.left_steps = right_steps, left_steps
        self.noop = press([])
        self.moves = {(False, False): press(["RIGHT"]), (False, True): press(["RIGHT", jump]),
                      (True, False): press(["LEFT"]), (True, True): press(["LEFT", jump])}
        self.sequences: list[Solution] = []
        self.timesteps = 0  # T
        #: What it did, as (kind, T at the start): "explore", "replay", "backtrack"; for tests and curiosity.
        self.events: list[tuple[str, int]] = []
        self._actions: list[Any] = []
        self._cumulative: list[float] = []

    def play(self) -> None:
        """Explore and replay until the env's budget ends the play."""
        new_episode = True
        while True:
            if new_episode:
                if self.sequences and self.rng.random() < self.beta + self.timesteps / self.budget:
                    best = self.best()
                    best.rewards.append(self.replay(best.actions))
                    continue
                self._reset()
                self.events.append(("explore", self.timesteps))
                new_episode = False
            gained, new_episode = self.move(self.right_steps, left=False)
            if not new_episode and gained <= 0:
                self.events.append(("backtrack", self.timesteps))
                _, new_episode = self.move(self.left_steps, left=True)
            if new_episode:
                self.sequences.append(Solution(self.best_prefix(), [max(self._cumulative)]))

    def best(self) -> Solution:
        """The sequence of highest mean reward (of equal means, the one ranked last before)."""
        self.sequences.sort(key=lambda s: s.mean)  # stable, as the baselines' sorted() was
        return self.sequences[-1]

    def move(self, steps: int, *, left: bool) -> tuple[float, bool]:
        """Run one way for ``steps`` steps, jumping now and then; return the reward and whether the episode ended."""
        total, jumping = 0.0, 0
        for _ in range(steps):
            if jumping > 0:
                jump, jumping = True, jumping - 1
            else:
                jump = self.rng.random() < self.jump_prob
                jumping = self.jump_repeat - 1 if jump else 0
            reward, done = self._step(self.moves[left, jump])
            total += reward
            if done:
                return total, True
        return total, False

    def replay(self, actions: list[Any]) -> float:
        """Play ``actions`` from a reset, then no-ops until the episode ends; return its total reward."""
        self._reset()
        self.events.append(("replay", self.timesteps))
        index, done = 0, False
        while not done:
            _, done = self._step(actions[index] if index < len(actions) else self.noop)
            index += 1
        return self._cumulative[-1] if self._cumulative else 0.0

    def best_prefix(self) -> list[Any]:
        """This episode's actions up to its first step of best cumulative reward."""
        best = max(self._cumulative)
        return self._actions[: self._cumulative.index(best) + 1]

    def _reset(self) -> None:
        self.env.reset()
        self._actions, self._cumulative = [], []

    def _step(self, action: Any) -> tuple[float, bool]:
        _, reward, terminated, truncated, _ = self.env.step(action)
        self.timesteps += 1
        self._actions.append(action)
        self._cumulative.append((self._cumulative[-1] if self._cumulative else 0.0) + float(reward))
        return float(reward), bool(terminated or truncated)


def jerk(env: gymnasium.Env, budget: int, seed: int) -> None:
    """The ``jerk`` agent: :class:`Jerk` with the paper's parameters."""
    Jerk(env, budget, random.Random(seed)).play()
