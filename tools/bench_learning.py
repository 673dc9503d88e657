#!/usr/bin/env python3
"""PPO's training speed on retrokit's vector env against stable-retro's envs, and the learning check on Dasher.

1. Speed (same machine, same run, in alternating rounds): timesteps per second
   of Stable-Baselines3's PPO (the ``quick`` config's hyper-parameters, the
   Nature CNN on gray 84x84 frames stacked 4, the seven actions) trained on
   Airstriker-Genesis (a game both libraries ship) with the benchmark's rules
   (frame skip 4, sticky 0.25):

   - ``retrokit``: ``make_vec(...).to_sb3()``, the native vector env with
     native preprocessing, under retrokit's learner view (:mod:`retrokit.learning.sb3task`);
   - ``stable-retro``: stable-retro's env in a Python sticky frame-skip wrapper
     (the paper's), Gymnasium's gray, resize and frame-stack wrappers and a
     discretizer, one per process of SB3's ``SubprocVecEnv``.

   Beside each rate, the env's share of a training step's time: the seconds
   PPO spent waiting for the envs' steps and resets over the seconds of
   ``learn``. The ratio retrokit/stable-retro is the median over rounds.

2. The learning check (``--learning``): ``retrokit evaluate --benchmark dasher
   --agent ppo --agent-config quick --levels Zone1.Act2 --timesteps 120000``
   and the same with ``--agent random``; PPO's last 20% of episodes must score
   at least 1.5 times random's mean. ``--learning-runs PPO_DIR RANDOM_DIR``
   reads two such run folders made before instead.

Usage: python tools/bench_learning.py [--envs 4] [--timesteps 2048] [--rounds 3] [--learning | --learning-runs P R]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import gymnasium
import numpy as np

GAME, STATE = "Airstriker-Genesis", "Level1"
RULES = {"frameskip": 4, "sticky_prob": 0.25, "max_episode_steps": 1000}
# Airstriker's ship: the paper's seven actions' shape on its pad (B fires).
ACTIONS = (("LEFT",), ("RIGHT",), ("LEFT", "DOWN"), ("RIGHT", "DOWN"), ("DOWN",), ("DOWN", "B"), ("B",))
LEARNING_ARGS = ["--benchmark", "dasher", "--levels", "Zone1.Act2", "--timesteps", "120000", "--workers", "1",
                 "--no-progress"]
LAST_SHARE, FACTOR = 0.2, 1.5


def sticky_retro_env():
    """stable-retro's env as the paper's code made it: a sticky frame skip in Python, then Gymnasium's wrappers."""
    import stable_retro
    from gymnasium.wrappers import FrameStackObservation, GrayscaleObservation, ResizeObservation, TimeLimit

    sys.path.insert(0, str(Path(__file__).parent))
    from bench_env import StickyFrameSkip

    class Sticky(gymnasium.Wrapper):
        def __init__(self, env):
            super().__init__(env)
            self.skip = StickyFrameSkip(env)

        def step(self, action):
            return self.skip.step(action)

    class Discrete(gymnasium.ActionWrapper):
        def __init__(self, env):
            super().__init__(env)
            buttons = env.unwrapped.buttons
            self.arrays = [np.array([b in combo for b in buttons], dtype=np.int8) for combo in ACTIONS]
            self.action_space = gymnasium.spaces.Discrete(len(ACTIONS))

        def action(self, action):
            return self.arrays[int(action)]

    env = stable_retro.make(f"{GAME}-v0", state=STATE, render_mode=None)
    env = TimeLimit(Discrete(Sticky(env)), RULES["max_episode_steps"])
    env = FrameStackObservation(ResizeObservation(GrayscaleObservation(env, keep_dim=False), (84, 84)), 4)
    return env


class Timed:
    """Wraps an SB3 VecEnv; adds up the seconds its steps and resets take."""

    @staticmethod
    def wrap(venv):
        from stable_baselines3.common.vec_env import VecEnvWrapper

        class TimedVecEnv(VecEnvWrapper):
            seconds = 0.0

            def reset(self):
                start = time.perf_counter()
                try:
                    return self.venv.reset()
                finally:
                    self.seconds += time.perf_counter() - start

            def step_async(self, actions):
                start = time.perf_counter()
                self.venv.step_async(actions)
                self.seconds += time.perf_counter() - start

            def step_wait(self):
                start = time.perf_counter()
                try:
                    return self.venv.step_wait()
                finally:
                    self.seconds += time.perf_counter() - start

        return TimedVecEnv(venv)


def make_retrokit(envs: int):
    import retrokit
    from retrokit.benchmark.definition import LearningTask
    from retrokit.learning.sb3task import TaskVecEnv

    native = retrokit.make_vec(GAME, envs, STATE, action_type="all", grayscale=True, resize=(84, 84), frame_stack=4,
                               channels_first=True, **RULES).to_sb3()
    return TaskVecEnv(native, LearningTask(ACTIONS), 0.005)


def make_stable_retro(envs: int):
    from stable_baselines3.common.vec_env import SubprocVecEnv, VecTransposeImage

    # Gymnasium's FrameStack puts the frames first: (4, 84, 84), what SB3's CNN takes.
    venv = SubprocVecEnv([sticky_retro_env] * envs, start_method="forkserver")
    return venv if venv.observation_space.shape[0] == 4 else VecTransposeImage(venv)


def rate(venv, timesteps: int) -> tuple[float, float]:
    """PPO's timesteps/s on ``venv`` over ``timesteps`` after one warm-up update, and the env's share of the time."""
    from retrokit.learning import ppo
    from retrokit.learning.config import load_config

    config = dict(load_config("ppo", "quick").values)
    config["horizon"] = max(32, timesteps // venv.num_envs // 4)  # four updates a measure
    config["minibatch"] = min(config["minibatch"], config["horizon"] * venv.num_envs)
    timed = Timed.wrap(venv)
    model = ppo.build(timed, config)
    model.learn(config["horizon"] * venv.num_envs)  # warm-up: caches, the first update's allocations
    timed.seconds = 0.0
    start = time.perf_counter()
    model.learn(timesteps, reset_num_timesteps=False)
    seconds = time.perf_counter() - start
    return timesteps / seconds, timed.seconds / seconds


def speed(envs: int, timesteps: int, rounds: int) -> None:
    ours, theirs = make_retrokit(envs), make_stable_retro(envs)
    rates: dict[str, list[tuple[float, float]]] = {"retrokit": [], "stable-retro": []}
    try:
        for _ in range(rounds):
            rates["retrokit"].append(rate(ours, timesteps))
            rates["stable-retro"].append(rate(theirs, timesteps))
    finally:
        ours.close()
        theirs.close()
    for name, values in rates.items():
        print(f"{name:>13}: {statistics.median(v[0] for v in values):7.1f} timesteps/s of PPO, "
              f"env {statistics.median(v[1] for v in values):.0%} of the time ({envs} envs; rounds: "
              + ", ".join(f"{v[0]:.1f}" for v in values) + ")")
    ratios = [a[0] / b[0] for a, b in zip(rates["retrokit"], rates["stable-retro"])]
    print(f"retrokit/stable-retro: {statistics.median(ratios):.2f}x (median of the rounds' ratios: "
          + ", ".join(f"{r:.2f}" for r in ratios) + ")")


def episodes(folder: Path) -> list[float]:
    return [json.loads(line)["reward"] for line in (folder / "episodes.jsonl").read_text().splitlines() if line]


def learning(ppo_dir: Path, random_dir: Path) -> bool:
    ours, theirs = episodes(ppo_dir), episodes(random_dir)
    last = ours[-max(1, round(len(ours) * LAST_SHARE)):]
    mean_last, mean_random = statistics.fmean(last), statistics.fmean(theirs)
    passed = mean_last >= FACTOR * mean_random
    print(f"PPO (quick): {len(ours)} episodes, mean {statistics.fmean(ours):.1f}, last {LAST_SHARE:.0%} "
          f"({len(last)} episodes) {mean_last:.1f}; random: {len(theirs)} episodes, mean {mean_random:.1f}; "
          f"ratio {mean_last / mean_random:.2f} (needs {FACTOR}): {'passed' if passed else 'FAILED'}")
    return passed


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--envs", type=int, default=4, help="envs of each kind")
    parser.add_argument("--timesteps", type=int, default=2048, help="timesteps of each measure")
    parser.add_argument("--rounds", type=int, default=3, help="rounds of measures")
    parser.add_argument("--no-speed", action="store_true", help="skip the speed part")
    parser.add_argument("--learning", action="store_true", help="run the learning check (about 10^5 timesteps)")
    parser.add_argument("--learning-runs", nargs=2, type=Path, metavar=("PPO_DIR", "RANDOM_DIR"),
                        help="read the learning check from these run folders")
    args = parser.parse_args()
    if not args.no_speed:
        speed(args.envs, args.timesteps, args.rounds)
    if args.learning_runs:
        return 0 if learning(*args.learning_runs) else 1
    if args.learning:
        folder = Path(tempfile.mkdtemp(prefix="bench-learning-"))
        for agent, extra in (("ppo", ["--agent-config", "quick"]), ("random", [])):
            subprocess.run([sys.executable, "-m", "retrokit", "evaluate", "--agent", agent, *extra, *LEARNING_ARGS,
                            "--out", str(folder / agent)], check=True)
        return 0 if learning(folder / "ppo", folder / "random") else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
