"""A vector env that steps N emulators in one process, on threads.

The native host releases the GIL while frames run, so N threads emulate on N
CPU cores; only the short Python part of each step is serial. It follows
``gymnasium.vector.VectorEnv`` with next-step autoreset, like Gymnasium's own
vector envs: the step after an episode ends resets that env and returns its
first observation with reward 0.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import gymnasium
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space, concatenate, create_empty_array, iterate

from retrokit.errors import InvalidArgumentError


class ThreadedVectorEnv(VectorEnv):
    """Steps several envs at once, one thread each.

    Args:
        env_fns: Functions that each make one env; all must have the same spaces.
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, env_fns: Sequence[Callable[[], gymnasium.Env]]) -> None:
        if not env_fns:
            raise InvalidArgumentError("Expected at least one env function, got none.")
        self.envs = [fn() for fn in env_fns]
        self.num_envs = len(self.envs)
        first = self.envs[0]
        for i, env in enumerate(self.envs[1:], 1):
            if env.observation_space != first.observation_space or env.action_space != first.action_space:
                raise InvalidArgumentError(
                    f"Expected every env to have env 0's spaces ({first.observation_space}, {first.action_space}); "
                    f"env {i} has ({env.observation_space}, {env.action_space}). Use the same game and options."
                )
        self.metadata = {**first.metadata, "autoreset_mode": AutoresetMode.NEXT_STEP}
        self.render_mode = first.render_mode
        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._observations = create_empty_array(self.single_observation_space, self.num_envs)
        self._rewards = np.zeros(self.num_envs, dtype=np.float64)
        self._terminations = np.zeros(self.num_envs, dtype=np.bool_)
        self._truncations = np.zeros(self.num_envs, dtype=np.bool_)
        self._autoreset = np.zeros(self.num_envs, dtype=np.bool_)
        # The calling thread steps env 0 itself; the pool steps the rest.
        self._pool = ThreadPoolExecutor(max_workers=max(self.num_envs - 1, 1), thread_name_prefix="retrokit-env")

    def _each(self, job: Callable[[int], Any]) -> list[Any]:
        futures = [self._pool.submit(job, i) for i in range(1, self.num_envs)]
        return [job(0)] + [f.result() for f in futures]

    def reset(self, *, seed: int | Sequence[int | None] | None = None, options: dict[str, Any] | None = None):
        seeds = [None if seed is None else seed + i for i in range(self.num_envs)] if not isinstance(seed, Sequence) else list(seed)
        if len(seeds) != self.num_envs:
            raise InvalidArgumentError(f"Expected {self.num_envs} seeds, got {len(seeds)}.")
        results = self._each(lambda i: self.envs[i].reset(seed=seeds[i], options=options))
        infos: dict[str, Any] = {}
        for i, (_, info) in enumerate(results):
            infos = self._add_info(infos, info, i)
        self._autoreset[:] = False
        self._observations = concatenate(self.single_observation_space, [r[0] for r in results], self._observations)
        return self._observations.copy(), infos

    def step(self, actions: Any):
        actions = list(iterate(self.action_space, actions))

        def one(i: int) -> tuple[Any, float, bool, bool, dict[str, Any]]:
            if self._autoreset[i]:
                obs, info = self.envs[i].reset()
                return obs, 0.0, False, False, info
            return self.envs[i].step(actions[i])

        results = self._each(one)
        infos: dict[str, Any] = {}
        for i, (_, reward, terminated, truncated, info) in enumerate(results):
            self._rewards[i], self._terminations[i], self._truncations[i] = reward, terminated, truncated
            infos = self._add_info(infos, info, i)
        self._observations = concatenate(self.single_observation_space, [r[0] for r in results], self._observations)
        self._autoreset = np.logical_or(self._terminations, self._truncations)
        return (
            self._observations.copy(),
            self._rewards.copy(),
            self._terminations.copy(),
            self._truncations.copy(),
            infos,
        )

    def render(self) -> tuple[Any, ...] | None:
        return tuple(env.render() for env in self.envs)

    def close_extras(self, **kwargs: Any) -> None:
        self._pool.shutdown(wait=True)
        for env in self.envs:
            env.close()


def make_vec(game: str, num_envs: int, state: Any = None, scenario: Any = None, **options: Any) -> ThreadedVectorEnv:
    """Make ``num_envs`` copies of a game's env stepped on threads."""
    from retrokit.env import State, make

    if num_envs < 1:
        raise InvalidArgumentError(f"Expected num_envs of 1 or more, got {num_envs}.")
    start = State.DEFAULT if state is None else state
    return ThreadedVectorEnv([lambda: make(game, start, scenario, **options) for _ in range(num_envs)])
