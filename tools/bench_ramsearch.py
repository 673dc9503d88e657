#!/usr/bin/env python3
"""Benchmark one RAM search filter over 64 KiB of RAM and every searched type.

Takes two real snapshots of Dasher's 64 KiB of work RAM (its first act, then
60 frames of running right), and times single filters on a fresh search,
where every position of all 38 types is still a candidate: the worst case. A
filter's time includes decoding both snapshots as every type, as the first
filter of a `retrokit ramsearch filter` process does. The baseline, measured
in the same run, is one numpy comparison of two int64 arrays of 64 Ki values
per type (what the simplest vectorised search would do at least). The target
is 20 ms a filter, judged on the fastest of the runs, as timeit advises:
slower runs measure the other processes sharing the CPU (the load average is
printed), not the filter. Exits with status 1 if a filter misses it.

Usage: PYTHONPATH=. python tools/bench_ramsearch.py [--runs 15]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from retrokit.ramsearch import RamSearch
from retrokit.ramsearch.engine import Engine

LIMIT_MS = 20.0
FILTERS = (("equal", 3, None), ("decreased", None, None), ("changed-by", -1, None), ("greater", 100, None),
           ("unchanged", None, "first"))  # fmt: skip


def snapshots() -> tuple[Engine, list[np.ndarray]]:
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        search.run(["RIGHT"], 60)
        return search.engine, [s.copy() for s in search.engine.snapshots]


def time_filter(template: Engine, rows: list[np.ndarray], spec: tuple, runs: int) -> list[float]:
    times = []
    for _ in range(runs):
        engine = Engine(template.layout, template.types)
        for row in rows:
            engine.add_snapshot(row)
        start = time.perf_counter()
        engine.filter(*spec)
        times.append(time.perf_counter() - start)
    return times


def time_baseline(rows: list[np.ndarray], types: int, runs: int) -> list[float]:
    a, b = (r.astype(np.int64) for r in rows)
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        for _ in range(types):
            np.not_equal(a, b)
        times.append(time.perf_counter() - start)
    return times


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=15)
    args = parser.parse_args()
    template, rows = snapshots()
    size, types = template.layout.size, len(template.types)
    baseline = min(time_baseline(rows, types, args.runs)) * 1e3
    print(f"RAM: {size // 1024} KiB, {types} types, {size * types:,} candidates; fastest of {args.runs} runs each")
    print(f"baseline: {types} int64 comparisons of {size // 1024} Ki values: {baseline:.2f} ms")
    print(f"load average: {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")
    worst = 0.0
    for spec in FILTERS:
        times = [t * 1e3 for t in time_filter(template, rows, spec, args.runs)]
        median = statistics.median(times)
        worst = max(worst, min(times))
        label = " ".join(str(p) for p in spec if p is not None)
        print(f"filter {label:<22} {min(times):6.2f} ms (median {median:.2f})   {min(times) / baseline:5.1f}x baseline")
    print(
        f"slowest filter, both snapshots decoded: {worst:.2f} ms (target <= {LIMIT_MS:.0f} ms): {'ok' if worst <= LIMIT_MS else 'OVER'}"
    )
    return 0 if worst <= LIMIT_MS else 1


if __name__ == "__main__":
    sys.exit(main())
