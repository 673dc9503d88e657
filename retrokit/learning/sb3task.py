"""The learner's view (:class:`~retrokit.learning.task.TaskView`) as Stable-Baselines3's ``VecEnvWrapper``.

Under it is any SB3 ``VecEnv`` of the benchmark's envs: retrokit's vector env
(``make_vec(...).to_sb3()``, what ``retrokit train`` trains on) or a
``DummyVecEnv`` of the one monitored env of a level (``retrokit evaluate``).
This module imports ``stable_baselines3``: only the SB3-based agents load it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from stable_baselines3.common.vec_env import VecEnv, VecEnvWrapper
from stable_baselines3.common.vec_env.base_vec_env import VecEnvStepReturn

from retrokit.benchmark.definition import LearningTask
from retrokit.learning.task import TaskView


class TaskVecEnv(VecEnvWrapper):
    """SB3's envs as the learner sees them: a ``Discrete`` choice of the task's actions, the scaled max-x reward.

    The infos stay the envs' own (the fields, ``terminal_observation``); the monitor under the envs, if any,
    still counts and scores the benchmark's reward.

    Args:
        venv: The envs (with ``action_type="all"``).
        task: The task's actions and x.
        reward_scale: The learner's reward is the max-x reward times this.
        on_episode: Called with ``(env index, benchmark reward, steps)`` when an episode ends.
    """

    def __init__(self, venv: VecEnv, task: LearningTask, reward_scale: float,
                 on_episode: Callable[[int, float, int], None] | None = None) -> None:
        first = venv.get_attr("unwrapped", [0])[0]
        self.view = TaskView(first, task, reward_scale, venv.num_envs, on_episode)
        super().__init__(venv, action_space=self.view.action_space)

    def reset(self) -> np.ndarray:
        obs = self.venv.reset()
        for i in range(self.num_envs):
            self.view.start(i, self.venv.reset_infos[i])
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self.venv.step_async(self.view.buttons(actions))

    def step_wait(self) -> VecEnvStepReturn:
        obs, rewards, dones, infos = self.venv.step_wait()
        learned = self.view.rewards(rewards, infos, dones)
        for i in np.flatnonzero(dones):
            self.view.start(int(i), self.venv.reset_infos[i])
        return obs, learned, dones, infos
