#!/usr/bin/env python3
"""Host speed: raw native frames/s against frames/s through the Python API.

The raw rate runs all frames in one native call, so per-call overhead
vanishes; the API rate runs the same frames 4 at a time through
``retrokit.host.emulator.Emulator.run``, as an env with frame skip 4 does. Both
start from Airstriker's Level1 state and are measured alternately in the same
run, several times, and the medians are compared: these machines are noisy,
so only the ratio means anything.

Usage: python tools/bench_host.py [--frames 4000] [--repeats 7] [--check]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import numpy as np

from retrokit.data.games import find_game
from retrokit.data.statecheck import load_state
from retrokit.host.emulator import Emulator
from retrokit.paths import wheel_dir

TARGET = 0.95


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=4000, help="frames per measurement (a multiple of 4)")
    parser.add_argument("--repeats", type=int, default=7, help="measurements of each kind")
    parser.add_argument("--check", action="store_true", help=f"exit 1 if the ratio is below {TARGET}")
    args = parser.parse_args()

    folder = wheel_dir() / "data" / "stable" / "Airstriker-Genesis-v0"
    state = load_state(find_game("Airstriker-Genesis"), folder / "Level1.state")  # the wheel's: no probe
    emu = Emulator("Genesis", folder / "rom.md")
    actions = np.zeros(emu.ports, dtype=np.uint16)
    calls = args.frames // 4

    def raw() -> float:
        emu.set_state(state)
        start = time.perf_counter()
        emu.handle.run(actions, calls * 4)  # one native call: the host's own rate
        return calls * 4 / (time.perf_counter() - start)

    def api() -> float:
        emu.set_state(state)
        run = emu.run
        start = time.perf_counter()
        for _ in range(calls):
            run(actions, 4)
        return calls * 4 / (time.perf_counter() - start)

    raw(), api()  # warm up caches and the branch predictor
    raws, apis = [], []
    for _ in range(args.repeats):
        raws.append(raw())
        apis.append(api())
    raw_median, api_median = statistics.median(raws), statistics.median(apis)
    ratio = api_median / raw_median
    print(f"raw native:          {raw_median:8.0f} frames/s (median of {args.repeats})")
    print(f"Python API, 4/call:  {api_median:8.0f} frames/s (median of {args.repeats})")
    print(f"ratio API/raw:       {ratio:8.3f}  (target >= {TARGET})")
    emu.close()
    return 1 if args.check and ratio < TARGET else 0


if __name__ == "__main__":
    sys.exit(main())
