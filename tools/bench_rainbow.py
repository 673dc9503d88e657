"""Rainbow's speed on Dasher, as ratios to the bare env in the same run: Tianshou's, and RLlib's DQN with --rllib.

Each phase plays Dasher-Genesis/Zone1.Act1 with the benchmark's rules and the learner's frames (84x84 gray, 4
stacked) and prints its steps per second and its ratio to the bare env's (random actions, no network):

- ``env``: the env alone, through the learner's view (the seven actions, the max-x reward);
- ``tianshou acting``: Tianshou's Rainbow choosing every action (Hessel et al.'s network), no updates;
- ``tianshou learning``: the same with an update of 32 transitions every 4 steps (the paper's ratio);
- with ``--rllib``: RLlib's DQN with the Rainbow settings (51 atoms, noisy, dueling, double Q, 3-step,
  prioritized replay), its env runner in this process, before and after learning starts;
- with ``--ray``: retrokit's RLlib Rainbow (:mod:`retrokit.learning.rllib_rainbow`, ``train --backend ray``'s:
  the local Rainbow's network in RLlib's DQN) on a local 2-CPU Ray, one env runner (a Ray actor), before and
  after learning starts.

The rates follow the machine and its load; the ratios carry over better. docs/learning.md has a run's figures.

    python tools/bench_rainbow.py --steps 1000 [--rllib] [--ray]
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import time

import numpy as np
import torch

from retrokit.benchmark.definition import load_benchmark
from retrokit.envs.env import make
from retrokit.learning.config import load_config
from retrokit.learning.rainbow import TaskEnv, build, observation_options, replay, run_steps
from retrokit.learning.task import learning_task

LEVEL = "Zone1.Act1"


def dasher_env(channels_first: bool = True) -> TaskEnv:
    benchmark = load_benchmark("dasher")
    config = load_config("rainbow").values
    options = {**benchmark.env_options(), **observation_options(config), "channels_first": channels_first}
    scenario = options.pop("scenario", None)
    return TaskEnv(make("Dasher-Genesis", LEVEL, scenario, **options), learning_task(benchmark), 1.0)


def rate(steps: int, seconds: float) -> float:
    return steps / max(seconds, 1e-9)


def bench_env(steps: int) -> float:
    env, rng = dasher_env(), np.random.default_rng(0)
    env.reset(seed=0)
    start = time.perf_counter()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(int(rng.integers(7)))
        if terminated or truncated:
            env.reset()
    seconds = time.perf_counter() - start
    env.close()
    return rate(steps, seconds)


def bench_tianshou(steps: int, *, learn: bool) -> float:
    from tianshou.data import Collector
    from tianshou.env import DummyVectorEnv

    config = {**load_config("rainbow").values, "learning_starts": 32, "replay": steps + 64}
    env = dasher_env()
    learner = build(config, env.observation_space.shape, 7)
    buffer = replay(config, 1)
    collector = Collector(learner.algorithm, DummyVectorEnv([lambda: env]), buffer, exploration_noise=True)
    collector.reset()
    run_steps(learner, collector, buffer, config, 1, learn=learn, until=lambda done: done >= 64)  # warm up
    start = time.perf_counter()
    run_steps(learner, collector, buffer, config, 1, learn=learn, until=lambda done: done >= steps)
    return rate(steps, time.perf_counter() - start)


def bench_rllib(steps: int) -> tuple[float, float]:
    """RLlib's DQN, Rainbow settings, its env runner in this process: (steps/s before learning, after)."""
    import gymnasium
    from ray.rllib.algorithms.dqn import DQNConfig
    from ray.tune.registry import register_env

    class Floats(gymnasium.ObservationWrapper):  # RLlib's default CNN takes float32 frames, channels last
        def __init__(self, env: gymnasium.Env) -> None:
            super().__init__(env)
            self.observation_space = gymnasium.spaces.Box(0.0, 1.0, env.observation_space.shape, np.float32)

        def observation(self, observation):
            return observation.astype(np.float32) / 255.0

    register_env("dasher-rainbow-bench", lambda _: Floats(dasher_env(channels_first=False)))
    config = (
        DQNConfig().environment("dasher-rainbow-bench")
        .env_runners(num_env_runners=0, num_envs_per_env_runner=1, rollout_fragment_length=4)
        .training(lr=6.25e-5, adam_epsilon=1.5e-4, num_atoms=51, v_min=-200.0, v_max=200.0, noisy=True, sigma0=0.5,
                  dueling=True, double_q=True, n_step=3, gamma=0.99, train_batch_size_per_learner=32,
                  target_network_update_freq=8192, num_steps_sampled_before_learning_starts=steps,
                  replay_buffer_config={"type": "PrioritizedEpisodeReplayBuffer", "capacity": 4 * steps,
                                        "alpha": 0.5, "beta": 0.4},
                  epsilon=[(0, 0.0), (1, 0.0)])
        .reporting(min_sample_timesteps_per_iteration=steps // 4)
        .debugging(seed=0)
    )  # fmt: skip
    return rllib_rates(config.build_algo(), steps)


def rllib_rates(algo, steps: int) -> tuple[float, float]:
    """Train ``algo`` (learning from ``steps`` on) for twice ``steps``: (steps/s before learning, after); stop it."""
    try:
        marks = [(time.perf_counter(), 0)]
        while marks[-1][1] < 2 * steps:
            result = algo.train()
            marks.append((time.perf_counter(), int(result["env_runners"]["num_env_steps_sampled_lifetime"])))
    finally:
        algo.stop()
    start, learning = marks[0], next(mark for mark in marks if mark[1] >= steps)
    return (rate(learning[1] - start[1], learning[0] - start[0]),
            rate(marks[-1][1] - learning[1], marks[-1][0] - learning[0]))


def bench_ray(steps: int) -> tuple[float, float]:
    """retrokit's RLlib Rainbow (rllib_rainbow) on a local 2-CPU Ray, one env runner: (before learning, after)."""
    import ray
    from ray import cloudpickle
    from ray.tune.registry import register_env

    from retrokit.learning import rllib_rainbow

    config = {**load_config("rainbow").values, "learning_starts": steps, "replay": 4 * steps}
    ray.init(address="local", num_cpus=2, include_dashboard=False, log_to_driver=False, logging_level="ERROR")
    try:
        cloudpickle.register_pickle_by_value(sys.modules[__name__])  # the env runner cannot import this script
        register_env("dasher-rainbow-ray", lambda _: dasher_env())
        dqn = rllib_rainbow.algorithm_config(config, "dasher-rainbow-ray", 1, 1, 0)
        return rllib_rates(dqn.reporting(min_sample_timesteps_per_iteration=steps // 4).build_algo(), steps)
    finally:
        ray.shutdown()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=1000, help="steps a phase (default: 1000)")
    parser.add_argument("--rllib", action="store_true", help="also RLlib's DQN with the Rainbow settings")
    parser.add_argument("--ray", action="store_true",
                        help="also retrokit's RLlib Rainbow (train --backend ray's) on a local 2-CPU Ray")
    args = parser.parse_args()
    torch.manual_seed(0)
    print(f"{os.cpu_count()} CPUs, /proc/loadavg {loadavg()}, torch threads {torch.get_num_threads()}", flush=True)
    base = bench_env(args.steps)

    def show(name: str, value: float) -> None:  # as each phase ends: a long RLlib phase keeps what came before
        print(f"{name:24s} {value:8.1f} steps/s  {value / base:6.3f} x the env  (load {os.getloadavg()[0]:.1f})",
              flush=True)

    show("env (random actions)", base)
    show("tianshou acting", bench_tianshou(args.steps, learn=False))
    show("tianshou learning", bench_tianshou(args.steps, learn=True))
    if args.rllib:
        os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
        sampling, learning = bench_rllib(args.steps)
        show("rllib acting", sampling)
        show("rllib learning", learning)
    if args.ray:
        os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
        sampling, learning = bench_ray(args.steps)
        show("ray rainbow acting", sampling)
        show("ray rainbow learning", learning)
    print(f"peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB, /proc/loadavg {loadavg()}")


def loadavg() -> str:
    """The machine's load, as /proc/loadavg gives it (the rates follow it)."""
    try:
        with open("/proc/loadavg") as file:
            return file.read().strip()
    except OSError:
        return f"{os.getloadavg()[0]:.1f}"


if __name__ == "__main__":
    main()
