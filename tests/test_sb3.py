"""`make_vec(...).to_sb3()`: SB3's VecEnv over retrokit's vector env, episode for episode SB3's own DummyVecEnv."""

from __future__ import annotations

import functools

import numpy as np
import pytest

import retrokit

pytest.importorskip("stable_baselines3", reason="needs stable-baselines3 and torch: pip install torch==2.13.0 stable-baselines3 (the CPU wheel; docs/evaluate.md)")
from stable_baselines3.common.vec_env import DummyVecEnv  # noqa: E402

# Short episodes, sticky actions and frame skip: several autoresets, each drawing on the env's own RNG.
OPTIONS = {"obs_type": "ram", "action_type": "discrete", "frameskip": 4, "sticky_prob": 0.25, "max_episode_steps": 40}


def test_episodes_equal_dummy_vec_envs_over_the_same_envs_and_seeds() -> None:
    ours = retrokit.make_vec("Dasher-Genesis", 3, **OPTIONS).to_sb3()
    theirs = DummyVecEnv([functools.partial(retrokit.make, "Dasher-Genesis", **OPTIONS)] * 3)
    try:
        for env in (ours, theirs):
            env.seed(7)
        obs = ours.reset()
        assert (obs == theirs.reset()).all() and ours.reset_infos == theirs.reset_infos
        rng = np.random.default_rng(0)
        episodes = 0
        for step in range(150):
            actions = rng.integers(0, ours.action_space.n, size=3)
            ours.step_async(actions)
            theirs.step_async(actions)
            o, r, d, i = ours.step_wait()
            to, tr, td, ti = theirs.step_wait()
            assert (o == to).all() and (r == tr).all() and (d == td).all(), f"step {step}"
            assert r.dtype == tr.dtype and d.dtype == td.dtype
            for mine, other in zip(i, ti):
                assert mine.keys() == other.keys(), f"step {step}"
                for key in mine:
                    assert np.array_equal(mine[key], other[key]), f"step {step}: {key}"
            assert ours.reset_infos == theirs.reset_infos
            episodes += int(d.sum())
        assert episodes >= 6  # every env ended several episodes
    finally:
        ours.close()
        theirs.close()


def test_ppo_learns_through_it() -> None:
    from stable_baselines3 import PPO

    env = retrokit.make_vec("Dasher-Genesis", 2, **OPTIONS).to_sb3()
    model = PPO("MlpPolicy", env, n_steps=32, batch_size=32, n_epochs=1, device="cpu", seed=0)
    model.learn(total_timesteps=128)
    assert model.num_timesteps == 128
    env.close()
