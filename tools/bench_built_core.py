#!/usr/bin/env python3
"""How much faster a system's env runs on the core ``retrokit build-core`` makes than on the wheel's, in one run.

The figure ``retrokit demo``, ``retrokit evaluate``, ``retrokit cores`` and
the README quote comes from here: systems.yaml keeps it as the system's
``build_core`` entry (``speedup``, ``measured``).

One env of ``--game`` (default: Airstriker-Genesis, the wheel's free ROM),
frame skip 4, sticky actions 0.25, RGB observations, random actions (the
game's filtered set), reset when an episode ends. Each round runs two child
processes in turn, each timing ``--seconds`` of steps after a warm-up: one
with the built core (which it must find in the data folder) and one with the
wheel's (named by ``RETROKIT_CORES``), the same data folder for both, so any
game imported there runs (``--game Pong-Atari2600`` after ``retrokit import
--from ale-py``). The ratio is the median of the rounds' built/wheel; the load
average is printed before and after.

Usage: python tools/bench_built_core.py [--game Airstriker-Genesis] [--rounds 5] [--seconds 3]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def load() -> str:
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f}, {five:.2f}, {fifteen:.2f} ({os.cpu_count()} CPUs)"


def child(game: str, seconds: float) -> None:
    """Print the env's steps a second, and where its core came from, as JSON."""
    sys.path.insert(0, str(REPO))
    import numpy as np

    import retrokit
    from retrokit.host.cores import locate_core

    with retrokit.make(game, frameskip=4, sticky_prob=0.25) as env:
        env.reset(seed=0)
        env.action_space.seed(0)
        actions = [env.action_space.sample() for _ in range(1024)]

        def run(steps: int) -> None:
            for i in range(steps):
                if any(env.step(actions[i % len(actions)])[2:4]):
                    env.reset()

        run(200)
        steps, start = 0, time.perf_counter()
        while (elapsed := time.perf_counter() - start) < seconds:
            run(50)
            steps += 50
        origin = locate_core(env.unwrapped.emulator.system.core).origin
        assert np.isfinite(steps / elapsed)
    print(json.dumps({"rate": steps / elapsed, "origin": origin}))


def measure(game: str, seconds: float, cores: str | None) -> dict:
    env = dict(os.environ, PYTHONPATH=str(REPO))
    env.pop("RETROKIT_CORES", None)
    if cores is not None:
        env["RETROKIT_CORES"] = cores
    out = subprocess.run([sys.executable, __file__, "--child", game, str(seconds)], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--game", default="Airstriker-Genesis")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--seconds", type=float, default=3.0)
    parser.add_argument("--child", nargs=2, metavar=("GAME", "SECONDS"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.child[0], float(args.child[1]))
        return 0
    sys.path.insert(0, str(REPO))
    from retrokit.paths import wheel_cores_dir

    print(f"{args.game}, frame skip 4, sticky 0.25, RGB; env steps/s\nbefore: {load()}")
    built, wheel = [], []
    for r in range(args.rounds):
        ours, theirs = measure(args.game, args.seconds, None), measure(args.game, args.seconds, str(wheel_cores_dir()))
        if ours["origin"] != "built" or theirs["origin"] != "RETROKIT_CORES":
            print(f"Expected the built core and the wheel's; found {ours['origin']} and {theirs['origin']}: "
                  "run retrokit build-core first.")
            return 1
        built.append(ours["rate"])
        wheel.append(theirs["rate"])
        print(f"  round {r + 1}: built {ours['rate']:,.0f}  wheel {theirs['rate']:,.0f}  "
              f"{ours['rate'] / theirs['rate']:.2f}x  ({load()})", flush=True)
    ratio = statistics.median(a / b for a, b in zip(built, wheel, strict=True))
    print(f"built {statistics.median(built):,.0f}  wheel {statistics.median(wheel):,.0f}  "
          f"ratio (median of the rounds') {ratio:.2f}x\nafter: {load()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
