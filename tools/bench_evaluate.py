#!/usr/bin/env python3
"""Evaluation throughput against the bare env's, in one run, and the Sonic protocol's time on this machine.

The evaluation plays the Dasher benchmark's test levels (the Dasher rules:
frame skip 4, sticky actions 0.25) with an agent for ``--timesteps`` each,
with 1 worker and with 2. The bare env is the same: the same levels, the
same agent and seeds, in as many processes, with nothing around the env but
the stop at the budget. So the ratio evaluation / bare is what the evaluator
costs: its monitor, episode log, messages, watchdog, progress and processes.
Two rates are given for each:

- play: env steps per second of a level while it plays (its budget over the
  seconds from its env made to its budget spent), what a level of the
  paper's million timesteps sees; the target is evaluation / bare >= 0.9;
- run: all the levels' steps over the whole run's seconds, process start-up,
  env creation and (for the evaluation) the output files and plots included.

From the evaluation's play rate with 2 workers comes the estimated time of
the paper's protocol (11 test levels of 1M timesteps, a level in one process
from start to end: ceil(11 / workers) rounds), with 2 workers and with the
count that keeps both cores busy in every round (3), beside the target of 60
minutes on 2 cores and the machine's ceiling: the bare env's play rate with
one process alone times the usable cores, every core busy all along.

Each round runs every configuration once; the order flips from one round to
the next, so both sides of a ratio saw the same machine. The medians over
the rounds are reported. A loaded machine lowers every rate; compare ratios.

Last, a level's worker start: the seconds from starting the evaluator's own
worker process to its message that the env is made and the agent called,
against a spawned process that does nothing, in the same run.

Usage: python tools/bench_evaluate.py [--timesteps 10000] [--rounds 1] [--agent jerk] [--levels test]
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import statistics
import tempfile
import time
from pathlib import Path

TARGET_RATIO, TARGET_MINUTES, TARGET_CORES = 0.9, 60.0, 2


def bare_level(job: tuple[str, str, int, int, str]) -> tuple[int, float]:
    """Play one level with the agent on the bare env; return its timesteps and play seconds."""
    import gymnasium

    from retrokit.benchmark.agents import resolve_agent
    from retrokit.benchmark.definition import Level, load_benchmark
    from retrokit.benchmark.monitor import BudgetSpent
    from retrokit.envs.env import RetroEnv

    name, agent_name, budget, seed, benchmark_name = job
    level = Level.parse(name)
    options = load_benchmark(benchmark_name).env_options()
    env = RetroEnv(level.game, level.state, options.pop("scenario", None), **options)
    level_seed = level.seed(seed)

    class Budget(gymnasium.Wrapper):
        """Only the stop at the budget, and the first reset's seed, as the evaluation's monitor gives them."""

        steps, seeded = 0, False

        def reset(self, *, seed=None, options=None):
            if not self.seeded:
                seed, self.seeded = level_seed, True
            return self.env.reset(seed=seed, options=options)

        def step(self, action):
            if self.steps >= budget:
                raise BudgetSpent
            self.steps += 1
            return self.env.step(action)

    bare = Budget(env)
    bare.action_space.seed(level_seed)
    agent = resolve_agent(agent_name)
    began = time.perf_counter()
    try:
        agent(bare, budget, level_seed)
    except BudgetSpent:
        pass
    seconds = time.perf_counter() - began
    env.close()
    return bare.steps, seconds


def bare_run(levels: list[str], workers: int, timesteps: int, agent: str) -> tuple[float, float]:
    """The bare env's (play rate, run rate) over ``levels`` in ``workers`` processes, a level per process."""
    context = multiprocessing.get_context("spawn")
    jobs = [(name, agent, timesteps, 0, "dasher") for name in levels]
    began = time.perf_counter()
    with context.Pool(workers, maxtasksperchild=1) as pool:
        results = pool.map(bare_level, jobs, chunksize=1)
    wall = time.perf_counter() - began
    steps = sum(s for s, _ in results)
    return steps / sum(seconds for _, seconds in results), steps / wall


def evaluation_run(levels: list[str], workers: int, timesteps: int, agent: str) -> tuple[float, float]:
    """The evaluation's (play rate, run rate): a whole ``retrokit evaluate`` run on ``levels``."""
    from retrokit.benchmark.definition import load_benchmark
    from retrokit.benchmark.evaluation import Evaluation, evaluate

    benchmark = load_benchmark("dasher")
    with tempfile.TemporaryDirectory() as folder:
        evaluation = Evaluation(benchmark=benchmark, levels=benchmark.select(",".join(levels)), agent=agent,
                                out=Path(folder) / "run", budget=timesteps, workers=workers, progress=False)
        began = time.perf_counter()
        evaluate(evaluation)
        wall = time.perf_counter() - began
    speed = evaluation.speed()
    return speed.level_rate, speed.steps / wall


def nothing() -> None:
    """A spawned process that does nothing: the baseline of a worker's start."""


def worker_start(level: str) -> tuple[float, float]:
    """Seconds from starting a level's worker process (the evaluator's own, spawned) to its Started message,
    when its env is made and its agent is called; and the same for a spawned process that does nothing."""
    from retrokit.benchmark import local
    from retrokit.benchmark.definition import load_benchmark
    from retrokit.benchmark.level import LevelTask, Started

    context = multiprocessing.get_context("spawn")
    benchmark = load_benchmark("dasher")
    task = LevelTask(benchmark, benchmark.select(level)[0], "random", 10**9, 0)
    reader, writer = context.Pipe(duplex=False)
    began = time.perf_counter()
    process = context.Process(target=local._work, args=(task, writer, os.getpid()), daemon=True)
    process.start()
    writer.close()
    while not isinstance(reader.recv(), Started):
        pass
    started = time.perf_counter() - began
    process.kill()
    process.join()
    began = time.perf_counter()
    process = context.Process(target=nothing)
    process.start()
    process.join()
    return started, time.perf_counter() - began


def main() -> None:
    from retrokit.benchmark.definition import load_benchmark
    from retrokit.benchmark.speed import SONIC_BUDGET, SONIC_LEVELS, busy_workers, ceiling_minutes, protocol_minutes

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timesteps", type=int, default=10_000, help="timesteps per level (default: 10000, the benchmark's)")
    parser.add_argument("--rounds", type=int, default=1, help="rounds (default: 1)")
    parser.add_argument("--agent", default="jerk", help="the agent (default: jerk)")
    parser.add_argument("--levels", default="test", help="the Dasher levels (default: test, its 3 test levels)")
    args = parser.parse_args()
    levels = [level.name for level in load_benchmark("dasher").select(args.levels)]
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1

    configs = [("bare", 1), ("eval", 1), ("bare", 2), ("eval", 2)]
    rates: dict[tuple[str, int], list[tuple[float, float]]] = {config: [] for config in configs}
    print(f"{len(levels)} Dasher levels, {args.timesteps} timesteps each, agent {args.agent}; env steps per second")
    print(f"{'round':>5}  {'workers':>7}  {'eval play':>9}  {'bare play':>9}  {'ratio':>6}  {'eval run':>8}  "
          f"{'bare run':>8}  {'ratio':>6}")
    for round_ in range(args.rounds):
        for kind, workers in configs if round_ % 2 == 0 else reversed(configs):
            run = evaluation_run if kind == "eval" else bare_run
            rates[kind, workers].append(run(levels, workers, args.timesteps, args.agent))
        for workers in (1, 2):
            (ep, er), (bp, br) = rates["eval", workers][-1], rates["bare", workers][-1]
            print(f"{round_ + 1:>5}  {workers:>7}  {ep:9.0f}  {bp:9.0f}  {ep / bp:6.3f}  {er:8.0f}  {br:8.0f}  "
                  f"{er / br:6.3f}")

    def median(kind: str, workers: int, which: int) -> float:
        return statistics.median(r[which] for r in rates[kind, workers])

    print()
    for workers in (1, 2):
        play = statistics.median(e[0] / b[0] for e, b in zip(rates["eval", workers], rates["bare", workers], strict=True))
        run = statistics.median(e[1] / b[1] for e, b in zip(rates["eval", workers], rates["bare", workers], strict=True))
        print(f"{workers} worker(s): evaluation / bare env, play {play:.3f} (target >= {TARGET_RATIO}), "
              f"whole run {run:.3f}")
    minutes = protocol_minutes(median("eval", 2, 0), 2, 2)  # 2 levels at once on 2 cores: a core each
    ceiling_rate = median("bare", 1, 0) * cores
    print(f"Sonic protocol ({SONIC_LEVELS} levels x {SONIC_BUDGET:,} timesteps), at the evaluation's "
          f"{median('eval', 2, 0):,.0f} steps/s per level with 2 workers: about {minutes:,.0f} minutes "
          f"(target <= {TARGET_MINUTES:g} on {TARGET_CORES} cores)")
    busy = busy_workers(TARGET_CORES)
    print(f"  with --workers {busy}, every round keeping the {TARGET_CORES} cores busy (the last round of 2 workers "
          f"plays one level alone): about {protocol_minutes(median('eval', 2, 0), busy, TARGET_CORES):,.0f} minutes")
    print(f"machine's ceiling: bare env {median('bare', 1, 0):,.0f} steps/s x {cores} usable core(s) = "
          f"{ceiling_rate:,.0f} steps/s, the protocol in {ceiling_minutes(median('bare', 1, 0), cores):,.0f} minutes")
    starts = [worker_start(levels[0]) for _ in range(5)]
    level_start, empty_start = statistics.median(s for s, _ in starts), statistics.median(e for _, e in starts)
    print(f"a level's worker start (spawned, imports, env made, agent called; median of 5): {level_start * 1000:,.0f} ms, "
          f"against {empty_start * 1000:,.0f} ms for a spawned process that does nothing ({level_start / empty_start:.1f}x)")


if __name__ == "__main__":
    main()
