#!/usr/bin/env python3
"""Env speed, as three ratios measured in one run on Airstriker.

1. retrokit's env (RGB observation, frame skip 4, sticky 0.25, reward, done
   and info) against the raw native rate of 4-frame runs (target >= 0.95).
2. The same env against stable-retro's env in a Python sticky frame-skip
   wrapper like the paper's (target >= 1.3; the core caps it near 1.36).
3. A 2-env threaded vector against 1 env, in env steps/s (target >= 1.85).

Beside the third it prints the machine's own ceiling, measured in the same
rounds: two bare emulators run at once by the native runner against one. On
a virtual machine whose second vCPU is often busy elsewhere, that ceiling
falls well below 2, and no vector env can beat it.

These machines are noisy and their speed drifts, so each round measures every
kind briefly, one right after another, and a ratio is taken within each round;
the median of those per-round ratios is reported.

Usage: python tools/bench_env.py [--steps 200] [--rounds 15] [--check]
"""

from __future__ import annotations

import argparse
import gzip
import statistics
import sys
import time

import numpy as np

import retrokit
from retrokit.emulator import Emulator
from retrokit.native import _host
from retrokit.paths import wheel_dir

GAME = "Airstriker-Genesis"
OPTIONS = {"frameskip": 4, "sticky_prob": 0.25, "obs_type": "rgb"}
TARGETS = {"env/raw": 0.95, "env/stable-retro": 1.3, "vector2/env": 1.85}
CEILINGS = {"vector2/env": "raw2/raw"}


class Raw:
    """The host alone: one warmed emulator, 4-frame runs in one native call."""

    def __init__(self) -> None:
        folder = wheel_dir() / "data" / "stable" / "Airstriker-Genesis-v0"
        self.emu = Emulator("Genesis", folder / "rom.md")
        self.state = gzip.decompress((folder / "Level1.state").read_bytes())
        self.actions = np.zeros(2, dtype=np.uint16)

    def steps_per_second(self, steps: int) -> float:
        self.emu.set_state(self.state)
        start = time.perf_counter()
        self.emu._emu.run(self.actions, 4 * steps)  # no per-step cost at all
        return steps / (time.perf_counter() - start)


class RawPair:
    """Two bare emulators stepped 4 frames at a time, both at once, by the native runner."""

    def __init__(self, raw: Raw) -> None:
        self.raw = raw
        self.emus = [Emulator("Genesis", raw.emu.rom) for _ in range(2)]
        self.runner = _host.Runner(1)
        self.actions = np.zeros((2, 2), dtype=np.uint16)

    def steps_per_second(self, steps: int) -> float:
        natives = [emu._emu for emu in self.emus]
        for emu in self.emus:
            emu.set_state(self.raw.state)
        start = time.perf_counter()
        for _ in range(steps // 2):
            self.runner.run(natives, self.actions, 4)
        return (steps // 2) * 2 / (time.perf_counter() - start)


def env_steps_per_second(env, steps: int) -> float:
    env.reset(seed=0)
    action = env.action_space.sample() * 0
    start = time.perf_counter()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            env.reset()
    return steps / (time.perf_counter() - start)


def vector_steps_per_second(vec, steps: int) -> float:
    vec.reset(seed=0)
    actions = np.zeros((vec.num_envs,) + vec.single_action_space.shape, dtype=vec.single_action_space.dtype)
    start = time.perf_counter()
    for _ in range(steps):
        vec.step(actions)
    return steps * vec.num_envs / (time.perf_counter() - start)


class StickyFrameSkip:
    """The paper's sticky frame-skip wrapper, in Python, around stable-retro's env."""

    def __init__(self, env, n: int = 4, stickprob: float = 0.25) -> None:
        self.env, self.n, self.stickprob = env, n, stickprob
        self.rng = np.random.default_rng(0)
        self.curac = None
        self.action_space = env.action_space

    def reset(self, **kwargs):
        self.curac = None
        return self.env.reset(**kwargs)

    def step(self, ac):
        total, terminated, truncated, info = 0.0, False, False, {}
        for i in range(self.n):
            if self.curac is None or (i == 0 and self.rng.random() > self.stickprob) or i == 1:
                self.curac = ac
            obs, rew, terminated, truncated, info = self.env.step(self.curac)
            total += rew
            if terminated or truncated:
                break
        return obs, total, terminated, truncated, info


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=200, help="env steps per measurement")
    parser.add_argument("--rounds", type=int, default=15, help="rounds of measurements")
    parser.add_argument("--check", action="store_true", help="exit 1 if a ratio misses its target")
    args = parser.parse_args()

    env = retrokit.make(GAME, **OPTIONS)
    vec = retrokit.make_vec(GAME, 2, **OPTIONS)
    try:
        import stable_retro

        reference = StickyFrameSkip(stable_retro.make("Airstriker-Genesis-v0", render_mode=None))
    except ImportError:
        reference = None

    raw = Raw()
    pair = RawPair(raw)
    kinds = {
        "raw": lambda: raw.steps_per_second(args.steps),
        "raw2": lambda: pair.steps_per_second(args.steps),
        "env": lambda: env_steps_per_second(env, args.steps),
        "vector2": lambda: vector_steps_per_second(vec, args.steps // 2),
    }
    if reference is not None:
        kinds["stable-retro"] = lambda: env_steps_per_second(reference, args.steps)
    for measure in kinds.values():
        measure()  # warm up
    samples: dict[str, list[float]] = {k: [] for k in kinds}
    for _ in range(args.rounds):
        for kind, measure in kinds.items():
            samples[kind].append(measure())
    for kind, values in samples.items():
        print(f"{kind:>14}: {statistics.median(values):8.1f} steps/s (median of {args.rounds})")
    failed = False
    for name, target in TARGETS.items():
        top, bottom = name.split("/")
        if bottom not in samples:
            print(f"{name:>18}: skipped (stable-retro is not installed)")
            continue
        ratio = statistics.median(t / b for t, b in zip(samples[top], samples[bottom]))
        ok = ratio >= target
        failed |= not ok
        print(f"{name:>18}: {ratio:6.3f}  (median of per-round ratios; target >= {target}) {'ok' if ok else 'MISSED'}")
        if name in CEILINGS:
            top, bottom = CEILINGS[name].split("/")
            ceiling = statistics.median(t / b for t, b in zip(samples[top], samples[bottom]))
            print(f"{CEILINGS[name]:>18}: {ceiling:6.3f}  (this machine's ceiling for it, same rounds)")
    env.close()
    vec.close()
    raw.emu.close()
    for emu in pair.emus:
        emu.close()
    return 1 if args.check and failed else 0


if __name__ == "__main__":
    sys.exit(main())
