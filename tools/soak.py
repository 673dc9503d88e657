#!/usr/bin/env python3
"""Run a pytest selection again and again with every core kept busy, to show its tests do not depend on speed.

One CPU hog per core (a Python process spinning ``while 1: pass``, at normal
priority) runs for the whole soak, so each run sees a machine with no idle
core, slower than any test machine should be. Each run is a fresh
``python -m pytest -q -p no:cacheprovider SELECTION``; the tool prints each
run's result line and time as it ends, then a summary: runs failed, times
(min, median, max), and every test that failed with how many runs it failed in.

Usage: python tools/soak.py [--runs 10] [--hogs N] [--keep-going/--stop] -- tests/test_x.py [pytest options]

Exit status: 0 when every run passed, 1 otherwise.
"""

from __future__ import annotations

import argparse
import collections
import os
import re
import signal
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
HOG = "while 1: pass"
SUMMARY = re.compile(r"^=* ?(\d+ (passed|failed|error|errors|skipped|deselected|xfailed|xpassed)\b.*?) ?=*$")
FAILED = re.compile(r"^(FAILED|ERROR) (\S+)")


def start_hogs(count: int) -> list[subprocess.Popen]:
    """Start ``count`` busy-looping Python processes."""
    return [subprocess.Popen([sys.executable, "-c", HOG]) for _ in range(count)]


def stop_hogs(hogs: list[subprocess.Popen]) -> None:
    """End the hogs this tool started, each by its own process."""
    for hog in hogs:
        hog.kill()
    for hog in hogs:
        hog.wait()


def run_once(selection: list[str], log: Path) -> tuple[int, float, str, list[str]]:
    """Run pytest on ``selection`` once; return its exit status, seconds, result line and failed test ids."""
    started = time.monotonic()
    with log.open("w") as out:
        run = subprocess.Popen([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *selection],
                               cwd=REPO, stdout=out, stderr=subprocess.STDOUT)  # fmt: skip
        try:
            code = run.wait()
        finally:
            if run.poll() is None:  # the soak was stopped: its run stops with it
                run.terminate()
                run.wait()
    seconds = time.monotonic() - started
    lines = log.read_text(errors="replace").splitlines()
    result = next((m.group(1) for line in reversed(lines) if (m := SUMMARY.match(line.strip()))), "no result line")
    failed = [m.group(2) for line in lines if (m := FAILED.match(line))]
    return code, seconds, result, failed


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10, help="how many times to run the selection (10)")
    parser.add_argument("--hogs", type=int, default=os.cpu_count() or 1, help="busy processes (one per core)")
    parser.add_argument("--logs", type=Path, default=Path("/tmp/soak"), help="where each run's output goes")
    parser.add_argument("--stop", action="store_true", help="stop at the first failed run")
    parser.add_argument("selection", nargs="+", help="what to pass to pytest (after --)")
    args = parser.parse_args(argv)
    args.logs.mkdir(parents=True, exist_ok=True)

    print(f"soak: {args.runs} runs of pytest {' '.join(args.selection)} with {args.hogs} CPU hogs", flush=True)
    times: list[float] = []
    failures: collections.Counter[str] = collections.Counter()
    failed_runs = 0
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))  # kill PID: the hogs and the run end too
    hogs = start_hogs(args.hogs)
    try:
        for run in range(1, args.runs + 1):
            log = args.logs / f"run{run:02d}.log"
            code, seconds, result, failed = run_once(args.selection, log)
            times.append(seconds)
            failures.update(failed)
            failed_runs += code != 0
            print(f"run {run:2d}: {'ok    ' if code == 0 else 'FAILED'} {seconds:7.1f} s  {result}  ({log})",
                  flush=True)  # fmt: skip
            for test in failed:
                print(f"        failed: {test}", flush=True)
            if code != 0 and args.stop:
                break
    finally:
        stop_hogs(hogs)

    if not times:
        return 1
    print(f"soak: {failed_runs} of {len(times)} runs failed; time min {min(times):.1f} s, "
          f"median {statistics.median(times):.1f} s, max {max(times):.1f} s")  # fmt: skip
    for test, count in failures.most_common():
        print(f"  {test}: failed in {count} of {len(times)} runs")
    return 1 if failed_runs else 0


if __name__ == "__main__":
    sys.exit(main())
