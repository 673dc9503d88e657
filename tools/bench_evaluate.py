#!/usr/bin/env python3
"""Evaluation throughput: 2 workers against 1, beside this machine's own ceiling, in one run.

The evaluation plays two Dasher levels (JERK, the Dasher benchmark's rules)
for ``--timesteps`` each, once with one worker (both levels in this
process, one after the other) and once with two (this process plays one
level, a worker process the other). Its throughput is env steps per second over the whole run, from the
call to the written report: process start-up, env creation and the output
files included.

The ceiling is the same split without retrokit's evaluation around it: the
same frames run by bare emulators, both levels' worth in one process, then
one level's worth in each of two processes at once. A machine whose second
CPU is busy elsewhere cannot give the evaluation more than it gives the bare
emulators, so the target is a 2-worker speed-up of 1.8 or more, or, where the
ceiling is lower, within 5% of it (speed-up / ceiling >= 0.95).

Within a round each evaluation runs right after (or before) the bare run of
its own parallelism, and the order flips from one round to the next, so that
each comparison is between runs that saw the same machine; the medians over
the rounds are reported.

Usage: python tools/bench_evaluate.py [--timesteps 10000] [--rounds 3] [--agent jerk]
"""

from __future__ import annotations

import argparse
import multiprocessing
import statistics
import tempfile
import time
from pathlib import Path

LEVELS = "Zone2.Act2,Zone3.Act2"
TARGET, CEILING_SHARE = 1.8, 0.95


def bare(states: list[str], steps: int, start, done) -> None:  # two multiprocessing primitives
    """A process of bare emulators: ``steps`` 4-frame steps from each state, after ``start``; put the seconds."""
    from retrokit.data.games import find_game
    from retrokit.data.statecheck import load_state
    from retrokit.host.emulator import Emulator

    game = find_game("Dasher-Genesis")
    emulator = Emulator(game.system, game.require_rom())
    blobs = [load_state(game, game.state_path(state)) for state in states]
    start.wait()
    began = time.perf_counter()
    for blob in blobs:
        emulator.set_state(blob)
        for _ in range(steps):
            emulator.run(0x80, 4)  # RIGHT held, as the agents mostly do
    done.put(time.perf_counter() - began)
    emulator.close()


def bare_rate(processes: int, steps: int) -> float:
    """Bare emulator steps per second: both states in one process, or one state in each of two."""
    context = multiprocessing.get_context("spawn")
    states = ["Zone2.Act2", "Zone3.Act2"]
    parts = [states] if processes == 1 else [[s] for s in states]
    start, done = context.Event(), context.Queue()
    workers = [context.Process(target=bare, args=(part, steps, start, done)) for part in parts]
    for worker in workers:
        worker.start()
    time.sleep(1.0)  # let them import and load before the clock starts
    start.set()
    seconds = max(done.get(timeout=600) for _ in workers)
    for worker in workers:
        worker.join()
    return len(states) * steps / seconds


def evaluation_rate(workers: int, timesteps: int, agent: str) -> float:
    """Env steps per second of a whole ``retrokit evaluate`` run on the two levels."""
    from retrokit.benchmark.definition import load_benchmark
    from retrokit.benchmark.evaluation import Evaluation, evaluate

    benchmark = load_benchmark("dasher")
    with tempfile.TemporaryDirectory() as folder:
        began = time.perf_counter()
        summary = evaluate(Evaluation(benchmark=benchmark, levels=benchmark.select(LEVELS), agent=agent,
                                      out=Path(folder) / "run", budget=timesteps, workers=workers, progress=False))
        seconds = time.perf_counter() - began
    return sum(entry["timesteps"] for entry in summary["levels"].values()) / seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timesteps", type=int, default=10_000, help="timesteps per level (default: 10000, the benchmark's)")
    parser.add_argument("--rounds", type=int, default=3, help="rounds (default: 3)")
    parser.add_argument("--agent", default="jerk", help="the agent (default: jerk)")
    args = parser.parse_args()

    speedups, ceilings = [], []
    print(f"two Dasher levels, {args.timesteps} timesteps each, agent {args.agent}; env steps per second")
    print(f"{'round':>5}  {'eval 1':>8}  {'eval 2':>8}  {'bare 1':>8}  {'bare 2':>8}  {'eval 2/1':>8}  {'bare 2/1':>8}")
    for round_ in range(args.rounds):
        rates = {}
        # Each evaluation runs next to the bare run of its own parallelism, so that the two parts of
        # speed-up / ceiling = (eval2 / bare2) / (eval1 / bare1) each compare runs close in time.
        order = ["bare1", "eval1", "bare2", "eval2"] if round_ % 2 == 0 else ["eval2", "bare2", "eval1", "bare1"]
        for kind in order:
            n = int(kind[-1])
            if kind.startswith("eval"):
                rates[kind] = evaluation_rate(n, args.timesteps, args.agent)
            else:
                rates[kind] = bare_rate(n, args.timesteps)
        speedups.append(rates["eval2"] / rates["eval1"])
        ceilings.append(rates["bare2"] / rates["bare1"])
        print(f"{round_ + 1:>5}  {rates['eval1']:8.0f}  {rates['eval2']:8.0f}  {rates['bare1']:8.0f}  "
              f"{rates['bare2']:8.0f}  {speedups[-1]:8.3f}  {ceilings[-1]:8.3f}")
    speedup, ceiling = statistics.median(speedups), statistics.median(ceilings)
    share = statistics.median(s / c for s, c in zip(speedups, ceilings, strict=True))
    met = speedup >= TARGET or share >= CEILING_SHARE
    print(f"\n2 workers / 1 worker: {speedup:.3f} (target >= {TARGET})")
    print(f"machine's ceiling, 2 bare emulators in 2 processes / 1: {ceiling:.3f}")
    print(f"speed-up / ceiling: {share:.3f} (target >= {CEILING_SHARE})  ->  {'met' if met else 'NOT met'}")


if __name__ == "__main__":
    main()
