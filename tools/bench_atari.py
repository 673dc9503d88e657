#!/usr/bin/env python3
"""Benchmark retrokit's Atari 2600 env against stable-retro's and ale-py's own, on Pong, in one run.

Compared: steps per second of one Gymnasium env stepped with random actions,
RGB observations (210x160x3), no rendering, no sticky actions, in this
process, after a warm-up:

- ``retrokit``: ``retrokit.make("Pong-Atari2600")`` from its shipped state (stella);
- ``stable-retro``: ``stable_retro.make("Pong-Atari2600-v0")``, the same core, ROM and state;
- ``ale-py``: ``gymnasium.make("ALE/Pong-v5", repeat_action_probability=0)``, ALE's own Stella build.

At frame skip 1 each step runs one frame in all three. At frame skip 4,
retrokit and ALE run 4 frames a step themselves; stable-retro has no frame skip,
so its step is 4 of its steps (what a skip wrapper does). The ROM is ale-py's
pong.bin, imported into a temporary data folder. Each figure is the median of
``--runs`` timed runs of ``--steps`` steps; the ratios are retrokit's over the others'.

Then the cost of a reset on Breakout from its shipped state (resets per second:
the state load and the one frame after it), with ``reload_before_state`` as
systems.yaml has it (the game is unloaded and loaded again, as stable-retro
reloads stella), without it (a console reset only: what it saves, and what it
gets wrong), and stable-retro's ``env.reset()``.

Usage: PYTHONPATH=. python tools/bench_atari.py [--runs 5] [--steps 3000] [--resets 100]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))


def median_rate(step: Callable[[int], None], runs: int, steps: int) -> float:
    """Median steps per second of ``step(i)`` over ``runs`` runs of ``steps`` steps, after a warm-up run."""
    step(0)
    rates = []
    for _ in range(runs + 1):
        start = time.perf_counter()
        for i in range(steps):
            step(i)
        rates.append(steps / (time.perf_counter() - start))
    return statistics.median(rates[1:])


def retrokit_rate(frameskip: int, runs: int, steps: int) -> float:
    import retrokit

    with retrokit.make("Pong-Atari2600", frameskip=frameskip, action_type="all") as env:
        env.reset(seed=0)
        actions = np.random.default_rng(0).integers(0, 2, size=(steps, 8)).astype(np.int8)
        actions[:, 1:4] = 0  # no console switch
        return median_rate(lambda i: env.step(actions[i]), runs, steps)


def stable_retro_env(game: str, roms: Path) -> object:
    """stable-retro's env of ``game`` (its integration, with the ROM imported into ``roms``), every button."""
    import stable_retro
    from stable_retro.data import Integrations

    custom = Path(tempfile.mkdtemp(prefix="bench-atari-"))
    (custom / f"{game}-Atari2600-v0").mkdir()
    (custom / f"{game}-Atari2600-v0" / "rom.a26").symlink_to(roms / f"{game}-Atari2600" / "rom.a26")
    Integrations.add_custom_path(str(custom))
    return stable_retro.make(f"{game}-Atari2600-v0", inttype=Integrations.CUSTOM, render_mode=None,
                             use_restricted_actions=stable_retro.Actions.ALL)


def stable_retro_rate(frameskip: int, runs: int, steps: int, roms: Path) -> float:
    env = stable_retro_env("Pong", roms)
    try:
        env.reset(seed=0)
        actions = np.random.default_rng(0).integers(0, 2, size=(steps, 8)).astype(np.int8)
        actions[:, 1:4] = 0

        def step(i: int) -> None:
            for _ in range(frameskip):
                env.step(actions[i])

        return median_rate(step, runs, steps)
    finally:
        env.close()


def ale_rate(frameskip: int, runs: int, steps: int) -> float:
    import ale_py
    import gymnasium

    gymnasium.register_envs(ale_py)
    env = gymnasium.make("ALE/Pong-v5", frameskip=frameskip, repeat_action_probability=0.0, render_mode=None)
    try:
        env.reset(seed=0)
        actions = np.random.default_rng(0).integers(0, env.action_space.n, size=steps)
        return median_rate(lambda i: env.step(int(actions[i])), runs, steps)
    finally:
        env.close()


def retrokit_reset_rate(reload: bool, runs: int, resets: int, roms: Path) -> float:
    import dataclasses

    from retrokit.data.games import find_game
    from retrokit.data.statecheck import load_state
    from retrokit.host.emulator import Emulator
    from retrokit.host.systems import get_system

    game = find_game("Breakout-Atari2600")
    state = load_state(game, game.state_path())
    system = dataclasses.replace(get_system("Atari2600"), reload_before_state=reload)
    with Emulator(system, roms / "Breakout-Atari2600" / "rom.a26") as emulator:

        def reset(i: int) -> None:
            emulator.set_state(state)
            emulator.run(0, 1)

        return median_rate(reset, runs, resets)


def stable_retro_reset_rate(runs: int, resets: int, roms: Path) -> float:
    env = stable_retro_env("Breakout", roms)
    try:
        return median_rate(lambda i: env.reset(seed=0), runs, resets)
    finally:
        env.close()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--resets", type=int, default=100)
    args = parser.parse_args()
    data = Path(tempfile.mkdtemp(prefix="bench-atari-data-"))
    os.environ["RETROKIT_DATA"] = str(data)
    from retrokit.cli import main as cli

    if cli(["import", "--from", "ale-py"]) != 0:
        return 1
    print(f"\nPong, random actions, RGB observations; steps/s, median of {args.runs} runs of {args.steps} steps")
    print(f"{'frame skip':>10}  {'retrokit':>10}  {'stable-retro':>12}  {'ale-py':>10}  {'vs stable-retro':>15}  {'vs ale-py':>9}")
    for frameskip in (1, 4):
        ours = retrokit_rate(frameskip, args.runs, args.steps)
        theirs = stable_retro_rate(frameskip, args.runs, args.steps, data / "roms")
        ale = ale_rate(frameskip, args.runs, args.steps)
        print(f"{frameskip:>10}  {ours:>10,.0f}  {theirs:>12,.0f}  {ale:>10,.0f}  {ours / theirs:>14.2f}x  {ours / ale:>8.2f}x")
    reloaded = retrokit_reset_rate(True, args.runs, args.resets, data / "roms")
    reset_only = retrokit_reset_rate(False, args.runs, args.resets, data / "roms")
    theirs = stable_retro_reset_rate(args.runs, args.resets, data / "roms")
    print(f"\nBreakout, a state load and one frame; resets/s, median of {args.runs} runs of {args.resets} resets")
    print(f"{'retrokit (reload)':>18}  {'retrokit (console reset only)':>29}  {'stable-retro':>12}  "
          f"{'reload vs reset only':>20}  {'vs stable-retro':>15}")
    print(f"{reloaded:>18,.1f}  {reset_only:>29,.1f}  {theirs:>12,.1f}  {reloaded / reset_only:>19.3f}x  "
          f"{reloaded / theirs:>14.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
