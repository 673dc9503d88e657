#!/usr/bin/env python3
"""Benchmark the scenario DSL against the emulator it rides on.

Prints, for each Sonic game, the cost of one step of its contest reward and
done (``Run.step``), the median of several timed runs over a synthetic
trajectory; then the cost of one 4-frame emulator step (Airstriker, the free
Genesis ROM in the stable-retro wheel); then their ratio, which must stay
under 5%. Exits with status 1 if it does not.

Usage: PYTHONPATH=. python tools/bench_dsl.py [--runs 7] [--steps 20000]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from retrokit.dsl.scenario import load_scenario

GAMES = ("SonicTheHedgehog-Genesis", "SonicTheHedgehog2-Genesis", "SonicAndKnuckles3-Genesis")
LIMIT = 0.05


def trajectory(fields: list[str], steps: int) -> list[dict[str, int]]:
    """Field values of Sonic running right through Angel Island / Green Hill Act 1, never done."""
    base = dict.fromkeys(fields, 0)
    base.update(zone=0, act=0, lives=3)
    out = []
    for i in range(steps):
        x = 0x60 + (i % 2000) * 3
        out.append({**base, "x": x, "screen_x": max(0, x - 0xA0)})
    return out


def time_dsl(game: str, runs: int, steps: int) -> float:
    """Median seconds per ``Run.step`` of the game's contest scenario."""
    fields = list(yaml.safe_load((REPO / "games" / game / "game.yaml").read_text())["fields"])
    scenario = load_scenario(REPO / "games" / game / "contest.yaml", fields)
    values = trajectory(fields, 2000)
    results = []
    for _ in range(runs):
        run = scenario.start()
        run.reset(values[0])
        step = run.step
        start = time.perf_counter()
        for i in range(steps):
            step(values[i % 2000], 4 * i, i)
        results.append((time.perf_counter() - start) / steps)
    return statistics.median(results)


def time_emulator(runs: int, steps: int) -> float | None:
    """Median seconds per 4-frame step of Airstriker, or None if the emulator cannot run."""
    try:
        import stable_retro

        from retrokit.host.emulator import Emulator
    except ImportError as exc:
        print(f"emulator: not available ({exc})")
        return None
    rom = Path(stable_retro.__file__).parent / "data" / "stable" / "Airstriker-Genesis-v0" / "rom.md"
    emu = Emulator.for_rom(rom)
    try:
        emu.run([0], frames=60)  # past the boot
        results = []
        for _ in range(runs):
            start = time.perf_counter()
            for i in range(steps):
                emu.run([1 << 8 if i % 8 < 4 else 1 << 7], frames=4)
            results.append((time.perf_counter() - start) / steps)
        return statistics.median(results)
    finally:
        emu.close()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7, help="timed runs; the median is reported")
    parser.add_argument("--steps", type=int, default=20000, help="DSL steps per run")
    parser.add_argument("--emulator-steps", type=int, default=300, help="emulator steps per run")
    args = parser.parse_args(argv)

    dsl = {game: time_dsl(game, args.runs, args.steps) for game in GAMES}
    for game, seconds in dsl.items():
        print(f"DSL contest reward+done, {game:<28} {seconds * 1e6:7.2f} µs/step")
    emulator = time_emulator(args.runs, args.emulator_steps)
    if emulator is None:
        return 0
    print(f"emulator, 4 frames of Airstriker-Genesis        {emulator * 1e6:7.1f} µs/step")
    worst = max(dsl.values())
    ratio = worst / emulator
    verdict = "ok" if ratio < LIMIT else "TOO SLOW"
    print(f"DSL / emulator step: {ratio:.2%} (limit {LIMIT:.0%}): {verdict}")
    return 0 if ratio < LIMIT else 1


if __name__ == "__main__":
    sys.exit(main())
