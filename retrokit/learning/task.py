"""What a learner sees of a benchmark's envs: the task's actions, the max-x reward, the reward scale.

The task is one definition, the Sonic preset's: its seven actions
(:data:`retrokit.envs.sonic.ACTIONS`) and its reward preprocessing, the increase
of the episode's maximum x (:class:`retrokit.envs.sonic.MaxProgress`, behind
:class:`~retrokit.envs.sonic.AllowBacktracking`). A benchmark whose game is not
Sonic gives its own actions and x in its YAML's ``learning:`` block
(:class:`~retrokit.benchmark.definition.LearningTask`).

The rules of the benchmark never change: the env is the level's, with its frame
skip, sticky actions, episode length and scenario, and the score stays the
benchmark's reward, counted by the runner's monitor under the learner. Only what
the learner is given differs: its discrete choice pressed as the task's buttons
(the same arrays :class:`~retrokit.envs.sonic.Discretizer` sends), and its reward
the max-x reward times the config's ``reward_scale``. :class:`TaskView` does it
for N envs at once (a vector env's, or one), so PPO's training and its test runs
go through the same code; :class:`TaskEnv` is it as one Gymnasium env (Rainbow's envs, RLlib's env runners').
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import gymnasium
import numpy as np

from retrokit.benchmark.definition import Benchmark, LearningTask
from retrokit.envs.sonic import MaxProgress, press_each, progress_of
from retrokit.errors import InvalidArgumentError


def learning_task(benchmark: Benchmark) -> LearningTask:
    """The benchmark's learning task: its ``learning:`` block, or the Sonic preset's if its levels are Sonic's.

    Raises:
        InvalidArgumentError: The benchmark has no ``learning:`` block and is not of Sonic levels.
    """
    if benchmark.learning is not None:
        return benchmark.learning
    from retrokit.envs import sonic

    if all(level.game in sonic.GAMES for level in benchmark.levels()):
        return LearningTask(sonic.ACTIONS)
    raise InvalidArgumentError(
        f"Expected the benchmark {benchmark.name} to say what a learning agent plays, but it has no learning: "
        "block; add one to its YAML, e.g. learning: {actions: [[LEFT], [RIGHT], [RIGHT, B], [B]], x: p1_x} "
        "(see retrokit docs evaluate)."
    )


def image_options(config: Mapping[str, Any]) -> dict[str, Any]:
    """The native preprocessing a config's ``frame_size``, ``frame_stack`` and ``grayscale`` ask for (channels first)."""
    size = int(config["frame_size"])
    return {"grayscale": bool(config["grayscale"]), "resize": (size, size), "frame_stack": int(config["frame_stack"]),
            "channels_first": True}


class TaskView:
    """The learner's side of ``count`` envs: choices as buttons, rewards as the scaled max-x reward.

    Args:
        env: One of the envs (for its buttons: an env with ``action_type="all"``).
        task: The actions and x.
        reward_scale: What the max-x reward is multiplied by.
        count: How many envs.
        on_episode: Called with ``(env index, benchmark reward, steps)`` when an env's episode ends.
    """

    def __init__(self, env: gymnasium.Env, task: LearningTask, reward_scale: float, count: int,
                 on_episode: Callable[[int, float, int], None] | None = None) -> None:
        self.task, self.scale, self.count = task, float(reward_scale), count
        self.arrays = np.stack(press_each(env, task.actions))
        self.action_space = gymnasium.spaces.Discrete(len(task.actions))
        self.on_episode = on_episode
        self._progress = [MaxProgress() for _ in range(count)]
        self._returns = np.zeros(count)
        self._steps = np.zeros(count, dtype=np.int64)

    def buttons(self, choices: np.ndarray) -> np.ndarray:
        """The button arrays of each env's discrete choice."""
        choices = np.asarray(choices, dtype=np.int64).reshape(-1)
        if choices.size != self.count or choices.min(initial=0) < 0 or choices.max(initial=0) >= len(self.arrays):
            raise InvalidArgumentError(
                f"Expected {self.count} choices from 0 to {len(self.arrays) - 1}, got {choices.tolist()[:8]}."
            )
        return self.arrays[choices]

    def start(self, index: int, info: Mapping[str, Any]) -> None:
        """An episode of env ``index`` began, with ``info`` from its reset."""
        self._progress[index].start(progress_of(info, self.task.x))
        self._returns[index], self._steps[index] = 0.0, 0

    def rewards(self, rewards: Sequence[float], infos: Sequence[Mapping[str, Any]], dones: Sequence[bool]) -> np.ndarray:
        """The learner's rewards for a step of every env; record the benchmark's episodes that ended."""
        out = np.zeros(self.count, dtype=np.float32)
        for i in range(self.count):
            reward = float(rewards[i])
            self._returns[i] += reward
            self._steps[i] += 1
            tracker = self._progress[i]
            now = tracker.current + reward if self.task.x is None else progress_of(infos[i], self.task.x)
            out[i] = tracker.advance(now) * self.scale
            if dones[i] and self.on_episode is not None:
                self.on_episode(i, float(self._returns[i]), int(self._steps[i]))
        return out


class TaskEnv(gymnasium.Wrapper):
    """One env as the learner sees it (:class:`~retrokit.learning.task.TaskView`): the task's actions, its reward.

    Args:
        env: A level's env (``action_type="all"``), monitored or not.
        task: The actions and x.
        reward_scale: The learner's reward is the max-x reward times this.
        on_episode: Called with ``(env, benchmark reward, steps)`` when an episode ends.
    """

    def __init__(self, env: gymnasium.Env, task: LearningTask, reward_scale: float,
                 on_episode: Callable[[gymnasium.Env, float, int], None] | None = None) -> None:
        super().__init__(env)
        ended = None if on_episode is None else lambda _, reward, steps: on_episode(env, reward, steps)
        self.view = TaskView(env, task, reward_scale, 1, ended)
        self.action_space = self.view.action_space

    # The infos (every RAM field) are read here and not passed on: Rainbow's replay (and RLlib's episodes) would
    # keep them, 8 bytes a field a transition (Dasher's fields would add 6% to the frames).

    def reset(self, **kwargs: Any):
        obs, info = self.env.reset(**kwargs)
        self.view.start(0, info)
        return obs, {}

    def step(self, action: Any):
        obs, reward, terminated, truncated, info = self.env.step(self.view.buttons(np.asarray([action]))[0])
        learned = self.view.rewards([reward], [info], [terminated or truncated])[0]
        return obs, float(learned), terminated, truncated, {}
