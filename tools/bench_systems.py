"""Env steps per second on each system we have a cartridge for, beside stable-retro's on the same game.

For each cartridge of tools/cartridges.yaml (and Airstriker-Genesis, the wheel's free ROM), in one run:
retrokit's env (``retrokit.make``, RGB observations, frame skip 1 and 4) and stable-retro's env on an
integration of the same game (tests/stable_retro_game.py writes it), the same random button sets held
for 6 steps. It prints steps/s and retrokit's ratio to stable-retro's, and the machine's load average before
and after (the rates are the load's; the ratios, from the same run, carry over); docs/systems.md quotes the figures.
The env runs whichever core retrokit finds: one ``retrokit build-core`` made, if there is one (it says which).

    python tools/bench_systems.py [--steps 3000] [--games Dasher-Genesis,...]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "tests"))  # the integration writer the system tests use

import stable_retro
from stable_retro_game import pressed, wandering, write_integration

import retrokit
from retrokit.data.games import find_game
from retrokit.host.cores import locate_core


def load() -> str:
    """The machine's load average, which the rates depend on."""
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f}, {five:.2f}, {fifteen:.2f} ({os.cpu_count()} CPUs)"


def rate(env, steps: int, buttons: list, source, frameskip: int) -> float:
    """Steps per second over ``steps`` steps (the first 50 not timed)."""
    env.reset(seed=0)
    actions = [pressed(buttons, next(source)) for _ in range(steps + 50)]
    for action in actions[:50]:
        env.step(action)
    start = time.perf_counter()
    for action in actions[50:]:
        for _ in range(frameskip):  # stable-retro has no frame skip of its own; frameskip 1 for retrokit's
            _, _, done, truncated, _ = env.step(action)
            if done or truncated:
                env.reset(seed=0)
    return steps / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--games", default=",".join(["Airstriker-Genesis", *yaml.safe_load((REPO / "tools" / "cartridges.yaml").read_text())]))
    args = parser.parse_args()
    root = Path(tempfile.mkdtemp(prefix="bench-systems-"))
    stable_retro.data.Integrations.add_custom_path(str(root))
    print(load())
    print(f"{'game':<24} {'system':<10} {'screen':>8}  {'ours fs1':>9} {'theirs':>8} {'ratio':>6}  {'ours fs4':>9} {'theirs':>8} {'ratio':>6}")
    for name in args.games.split(","):
        game = find_game(name)
        wheel = name == "Airstriker-Genesis"
        integration = None if wheel else write_integration(game, root)
        row = []
        for frameskip in (1, 4):
            ours = retrokit.make(name, frameskip=frameskip, action_type="all")
            mine = rate(ours, args.steps, list(ours.buttons), wandering(game.system, 0), 1)
            height, width = ours.unwrapped.emulator.screen_shape()
            ours.close()
            theirs = stable_retro.make(
                f"{name}-v0" if wheel else integration.name, render_mode=None,
                use_restricted_actions=stable_retro.Actions.ALL,
                inttype=stable_retro.data.Integrations.STABLE if wheel else stable_retro.data.Integrations.CUSTOM_ONLY,
            )  # fmt: skip
            # stable-retro steps one frame a call: frameskip calls make one of our steps.
            other = rate(theirs, args.steps, list(theirs.unwrapped.buttons), wandering(game.system, 0), frameskip)
            theirs.close()
            row.append((mine, other))
        (a1, b1), (a4, b4) = row
        found = locate_core(game.system.core)
        print(f"{name:<24} {game.system.name:<10} {f'{width}x{height}':>8}  {a1:>9,.0f} {b1:>8,.0f} {a1 / b1:>5.2f}x"
              f"  {a4:>9,.0f} {b4:>8,.0f} {a4 / b4:>5.2f}x  ({found.origin} {game.system.core})")
    print(load())


if __name__ == "__main__":
    main()
