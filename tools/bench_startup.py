#!/usr/bin/env python3
"""Start-up time: ``import retrokit`` and ``retrokit --help`` against ``python -c pass``, in one run.

Each is a fresh interpreter, timed from its start to its exit, ``--runs``
times; the medians are printed in milliseconds with their ratio to the bare
interpreter's, which ran interleaved with them on the same machine. Targets:
``import retrokit`` and ``retrokit --help`` in at most 0.3 s. Also timed:
``import retrokit, gymnasium`` (what registers the Gymnasium ids) beside
``import gymnasium`` alone, so the ids' own cost shows.

The interpreters run with compiled bytecode, as an installed package has
(written on a first run into a folder of the temporary folder, even where
``PYTHONDONTWRITEBYTECODE`` is set, so that no checkout gets any).

``--against FOLDER`` times another checkout of retrokit too (its folder put
first on ``PYTHONPATH``, e.g. the main branch's), side by side.

Usage: python tools/bench_startup.py [--runs 15] [--against /path/to/other/checkout]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

TARGET_SECONDS = 0.3
CASES = {
    "python -c pass": "pass",
    "import retrokit": "import retrokit",
    "retrokit --help": "import sys; sys.argv = ['retrokit', '--help']; from retrokit.cli import main; main()",
    "import gymnasium": "import gymnasium",
    "import retrokit, gymnasium": "import retrokit, gymnasium",
}


def seconds(code: str, env: dict[str, str]) -> float:
    """Wall seconds of a fresh interpreter running ``code`` (its output thrown away).

    It runs in the temporary folder: ``python -c`` puts its working folder first on ``sys.path``, where a
    checkout would shadow the one asked for.
    """
    began = time.perf_counter()
    subprocess.run(
        [sys.executable, "-c", code], env=env, stdout=subprocess.DEVNULL, check=True, cwd=tempfile.gettempdir()
    )
    return time.perf_counter() - began


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=15, help="runs of each (default: 15)")
    parser.add_argument("--against", metavar="FOLDER", help="another retrokit checkout to time beside this one")
    args = parser.parse_args()
    # Compiled bytecode, as an installed package has: kept in a folder of its own, so no checkout gets any.
    base = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    base["PYTHONPYCACHEPREFIX"] = os.path.join(tempfile.gettempdir(), "retrokit-bench-startup-pycache")
    builds = {"this": base}
    if args.against:
        other = dict(base)
        other["PYTHONPATH"] = os.pathsep.join(p for p in (args.against, os.environ.get("PYTHONPATH")) if p)
        builds["against"] = other
    for env in builds.values():  # a first run of each builds any index and fills the page cache
        for code in CASES.values():
            seconds(code, env)
    times: dict[tuple[str, str], list[float]] = {(b, c): [] for b in builds for c in CASES}
    for _ in range(args.runs):  # interleaved, so every case saw the same machine
        for build, env in builds.items():
            for case, code in CASES.items():
                times[build, case].append(seconds(code, env))
    print(f"medians of {args.runs} runs, a fresh interpreter each ({sys.executable})")
    print(f"{'':28}" + "".join(f"{build:>22}" for build in builds))
    for case in CASES:
        row = ""
        for build in builds:
            median = statistics.median(times[build, case])
            base = statistics.median(times[build, "python -c pass"])
            row += f"{median * 1000:9.0f} ms {median / base:6.1f}x   "
        print(f"{case:28}{row}")
    for build in builds:
        verdicts = []
        for case in ("import retrokit", "retrokit --help"):
            median = statistics.median(times[build, case])
            verdicts.append(f"{case} {median:.3f} s ({'met' if median <= TARGET_SECONDS else 'missed'})")
        ids = statistics.median(times[build, "import retrokit, gymnasium"]) - statistics.median(
            times[build, "import gymnasium"]
        )
        print(f"{build}: {'; '.join(verdicts)}, target <= {TARGET_SECONDS} s; the ids and retrokit on top of "
              f"Gymnasium's import: {ids * 1000:.0f} ms")


if __name__ == "__main__":
    main()
