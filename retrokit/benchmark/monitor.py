"""The wrapper every agent plays through: it spends the budget and records episodes.

The runner hands an agent a :class:`Monitor` around the level's env. It counts
timesteps, seeds the first reset with the level's seed, checks every action,
and calls back with each finished episode. When the budget is spent, the next
``step`` raises :class:`BudgetSpent`, which ends the agent's play: an agent is
a plain loop over ``reset`` and ``step``, as in any Gymnasium code.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

import gymnasium
import numpy as np

from retrokit.errors import AgentError

#: At most this many frames of an episode are kept for its GIF; longer episodes keep every 2nd, 4th... frame.
MAX_GIF_FRAMES = 256
#: At most this many distinct valid actions are remembered as checked (a button pad has 4096 at 12 buttons).
MAX_CHECKED_ACTIONS = 4096


class BudgetSpent(BaseException):
    """The level's budget of timesteps is spent; the agent's play ends here.

    A ``BaseException``, like ``KeyboardInterrupt``, so an agent's own
    ``except Exception`` cannot swallow the end of its budget.
    """


@dataclass(frozen=True)
class Episode:
    """One finished episode of a level.

    Attributes:
        episode: Its number on the level, from 1.
        steps: Its timesteps.
        reward: Its total reward.
        timesteps: The level's timesteps so far, this episode's included.
        wall: Seconds since the level started.
    """

    episode: int
    steps: int
    reward: float
    timesteps: int
    wall: float

    def record(self, level: str) -> dict[str, Any]:
        """The episode as a line of ``episodes.jsonl``."""
        return {"level": level, **asdict(self)}

    @classmethod
    def from_record(cls, record: dict[str, Any], budget: int) -> Episode:
        """Read back a line of ``episodes.jsonl`` (see :meth:`record`) of a level with ``budget`` timesteps.

        Raises:
            ValueError: A field is missing, of the wrong type, or out of range (the message says which).
        """
        def whole(key: str, low: int, high: int) -> int:
            value = record.get(key)
            if not isinstance(value, int) or isinstance(value, bool) or not low <= value <= high:
                raise ValueError(f"'{key}' must be a whole number from {low} to {high}, got {value!r}")
            return value

        def real(key: str) -> float:
            value = record.get(key)
            if not isinstance(value, int | float) or isinstance(value, bool) or not math.isfinite(value):
                raise ValueError(f"'{key}' must be a finite number, got {value!r}")
            return float(value)

        return cls(whole("episode", 1, budget), whole("steps", 1, budget), real("reward"),
                   whole("timesteps", 1, budget), real("wall"))


class Monitor(gymnasium.Wrapper):
    """Counts, checks and records an agent's play of one level.

    Args:
        env: The level's env.
        level: The level's name, for error messages.
        budget: Timesteps the agent may take.
        seed: The seed of the first reset (and of the action space).
        on_episode: Called with each finished :class:`Episode`.
        keep_frames: Keep the frames of the best episode so far (:attr:`best_frames`), for a GIF.
    """

    def __init__(
        self,
        env: gymnasium.Env,
        level: str,
        budget: int,
        seed: int,
        on_episode: Callable[[Episode], None],
        *,
        keep_frames: bool = False,
    ) -> None:
        super().__init__(env)
        self.level, self.budget, self.seed = level, budget, seed
        self.on_episode, self.keep_frames = on_episode, keep_frames
        self.timesteps = self.episodes = 0
        self.best_reward: float | None = None
        self.best_frames: list[np.ndarray] = []
        self.best_stride = 1  # steps between two of best_frames
        self._reward, self._steps, self._ended, self._started = 0.0, 0, True, False
        self._frames: list[np.ndarray] = []
        self._stride = 1
        self._clock = time.perf_counter()
        self._valid: set[Any] = set()  # keys (see _action_key) of actions the action space accepted
        self.action_space.seed(seed)

    @property
    def timesteps_left(self) -> int:
        """Timesteps the agent may still take."""
        return self.budget - self.timesteps

    @property
    def seconds(self) -> float:
        """Seconds since the level started (its env made, before the agent's first call)."""
        return time.perf_counter() - self._clock

    @property
    def unfinished_reward(self) -> float:
        """The reward of the episode under way (0.0 when none is): what a level that finished none scores."""
        return 0.0 if self._ended else self._reward

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        """Start an episode; an unfinished one is dropped (only finished episodes score)."""
        if self.timesteps >= self.budget:
            raise BudgetSpent
        if not self._started:
            seed, self._started = (self.seed if seed is None else seed), True
        obs, info = self.env.reset(seed=seed, options=options)
        self._reward, self._steps, self._ended = 0.0, 0, False
        self._frames, self._stride = [], 1
        self._keep(obs)
        return obs, info

    def step(self, action: Any):
        """Take a step of the budget, checking the action first."""
        if self.timesteps >= self.budget:
            raise BudgetSpent
        if self._ended:
            raise AgentError(
                f"Expected reset() before step() at the start of an episode ({self._where()}), but the agent stepped "
                "a finished (or never started) episode; call env.reset() when terminated or truncated is true."
            )
        self._check(action)
        obs, reward, terminated, truncated, info = self.env.step(action)
        self.timesteps += 1
        self._steps += 1
        self._reward += float(reward)
        if self.keep_frames and self._steps % self._stride == 0:
            self._keep(obs)
        if terminated or truncated:
            self._finish()
        return obs, reward, terminated, truncated, info

    def _where(self) -> str:
        return f"level {self.level}, step {self.timesteps + 1}"

    def _check(self, action: Any) -> None:
        """Check ``action`` against the action space, once per distinct action: an agent repeats a few actions
        millions of times, and the space's check costs more than the rest of the monitor's step."""
        key = _action_key(action)
        if key is not None and key in self._valid:
            return
        if not self.action_space.contains(_as_array(action)):
            raise AgentError(
                f"Expected an action of {self.action_space} ({self._where()}), got {_describe(action)}; "
                "fix the agent's actions."
            )
        if key is not None and len(self._valid) < MAX_CHECKED_ACTIONS:
            self._valid.add(key)

    def _finish(self) -> None:
        self._ended = True
        self.episodes += 1
        if self.keep_frames and (self.best_reward is None or self._reward > self.best_reward):
            self.best_frames, self.best_stride = self._frames, self._stride
        if self.best_reward is None or self._reward > self.best_reward:
            self.best_reward = self._reward
        self._frames = []
        self.on_episode(Episode(self.episodes, self._steps, self._reward, self.timesteps,
                                round(self.seconds, 3)))

    def _keep(self, obs: Any) -> None:
        if not self.keep_frames or not (isinstance(obs, np.ndarray) and obs.ndim == 3):
            return
        self._frames.append(obs.copy())
        if len(self._frames) >= MAX_GIF_FRAMES:  # halve the frame rate rather than grow
            self._frames, self._stride = self._frames[::2], self._stride * 2


def _action_key(action: Any) -> Any:
    """What decides whether the action space accepts ``action``, as a hashable key; ``None`` if it cannot be made
    cheaply and exactly (an action of another type, or an array of objects, is checked every time)."""
    kind = type(action)
    if kind is int:
        return action
    if kind is np.ndarray and action.dtype.kind in "biuf":
        return action.dtype.str, action.shape, action.tobytes()
    return None


def _as_array(action: Any) -> Any:
    return np.asarray(action) if isinstance(action, list | tuple) else action


def _describe(action: Any) -> str:
    text = repr(action)
    if isinstance(action, np.ndarray):
        text = f"array {np.array2string(action.ravel()[:16], separator=',')} of shape {action.shape}, dtype {action.dtype}"
    return text if len(text) <= 120 else text[:117] + "..."
