"""Stable-Baselines3's ``VecEnv`` over retrokit's vector env: ``retrokit.make_vec(...).to_sb3()``.

SB3 trains on its own vector-env interface, not Gymnasium's. Its auto-reset
differs too: where an episode ends, SB3's ``step_wait`` returns that env's
*next* episode's first observation, the last one in
``info["terminal_observation"]``; Gymnasium's (and retrokit's) next-step
autoreset returns the last observation and resets on the following step.
So :meth:`SB3VecEnv.step_wait` steps every env in one call of the vector env
(the native batch) and, for the envs whose episode ended, sends the reset
step at once and takes its first observation. The episodes are exactly
those of SB3's ``DummyVecEnv`` over the same envs and seeds
(``tests/test_sb3.py``), at the vector env's speed.

This module imports ``stable_baselines3``: it is loaded only by
:meth:`~retrokit.envs.vector.ThreadedVectorEnv.to_sb3`.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from stable_baselines3.common.vec_env import VecEnv
from stable_baselines3.common.vec_env.base_vec_env import VecEnvIndices, VecEnvStepReturn

if TYPE_CHECKING:  # a name for the annotations only: vector imports this module, in to_sb3
    from retrokit.envs.vector import ThreadedVectorEnv


def _env_infos(infos: dict[str, Any], count: int) -> list[dict[str, Any]]:
    """Gymnasium's batched info (arrays, with ``_key`` masks) as SB3's list of one dict per env."""
    out: list[dict[str, Any]] = [{} for _ in range(count)]
    for key, values in infos.items():
        if key.startswith("_"):
            continue
        present = infos.get(f"_{key}")
        rows = _env_infos(values, count) if isinstance(values, dict) else values
        for i in range(count):
            if present is None or present[i]:
                out[i][key] = rows[i]
    return out


class SB3VecEnv(VecEnv):
    """A retrokit vector env as SB3's ``VecEnv``, for ``PPO(policy, env)`` and the rest of SB3.

    Args:
        venv: The vector env (from :func:`retrokit.make_vec`); closing this closes it.
    """

    def __init__(self, venv: ThreadedVectorEnv) -> None:
        self.venv = venv
        super().__init__(venv.num_envs, venv.single_observation_space, venv.single_action_space)
        self.render_mode = getattr(venv, "render_mode", None)
        self._actions: Any = None

    def reset(self) -> np.ndarray:
        """Reset every env, with the seeds and options :meth:`seed` and ``set_options`` gave (then forgotten)."""
        seeds = [None if s is None else int(s) for s in self._seeds] if any(s is not None for s in self._seeds) else None
        options = self._options[0] if self._options and self._options[0] else None
        obs, infos = self.venv.reset(seed=seeds, options=options)
        self.reset_infos = _env_infos(infos, self.num_envs)
        self._reset_seeds()
        self._reset_options()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self) -> VecEnvStepReturn:
        obs, rewards, terminated, truncated, infos = self.venv.step(self._actions)
        env_infos = _env_infos(infos, self.num_envs)
        dones = terminated | truncated
        for i, info in enumerate(env_infos):  # on every step, as SB3's own VecEnvs set it
            info["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
        ended = np.flatnonzero(dones)
        for i in ended:
            env_infos[i]["terminal_observation"] = obs[i].copy()
        if ended.size:
            # The vector env's next step of these envs is their reset (next-step autoreset): take it now,
            # as SB3 expects the next episode's first observation with the last step's reward.
            actions = np.stack([self.action_space.sample()] * ended.size)
            self.venv.send(actions, ended)
            first, _, _, _, reset_infos, ids = self.venv.recv()
            for k, i in enumerate(ids):
                obs[i] = first[k]
                self.reset_infos[i] = _env_infos(reset_infos, len(ids))[k]
        return obs, rewards.astype(np.float32), dones, env_infos

    def close(self) -> None:
        self.venv.close()

    def get_images(self) -> Sequence[np.ndarray | None]:
        return [env.render() for env in self.venv.envs]

    def _targets(self, indices: VecEnvIndices) -> list[Any]:
        return [self.venv.envs[i] for i in self._get_indices(indices)]

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        return [env.get_wrapper_attr(attr_name) for env in self._targets(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        for env in self._targets(indices):
            setattr(env.unwrapped, attr_name, value)

    def env_method(self, method_name: str, *method_args: Any, indices: VecEnvIndices = None, **method_kwargs: Any) -> list[Any]:
        return [env.get_wrapper_attr(method_name)(*method_args, **method_kwargs) for env in self._targets(indices)]

    def env_is_wrapped(self, wrapper_class: type, indices: VecEnvIndices = None) -> list[bool]:
        from stable_baselines3.common import env_util

        return [env_util.is_wrapped(env, wrapper_class) for env in self._targets(indices)]

    def _get_indices(self, indices: VecEnvIndices) -> Iterable[int]:
        if indices is None:
            return range(self.num_envs)
        return [indices] if isinstance(indices, int) else indices
