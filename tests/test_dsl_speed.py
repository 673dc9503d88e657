"""The Sonic contest reward and done must cost a few microseconds per step.

tools/bench_dsl.py compares this cost with a 4-frame emulator step (about
2 ms); here a generous bound, 25 µs, keeps the test stable on a busy machine
while still catching a fall back to tree walking (tens of µs and more).
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

import pytest
import yaml

from retrokit.dsl.scenario import load_scenario

REPO = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("game", ["SonicTheHedgehog-Genesis", "SonicAndKnuckles3-Genesis"])
def test_contest_step_costs_microseconds(game: str) -> None:
    fields = list(yaml.safe_load((REPO / "games" / game / "game.yaml").read_text())["fields"])
    scenario = load_scenario(REPO / "games" / game / "contest.yaml", fields)
    values = [{**dict.fromkeys(fields, 0), "lives": 3, "x": 0x60 + i, "screen_x": i} for i in range(1000)]
    timings = []
    for _ in range(5):
        run = scenario.start()
        run.reset(values[0])
        start = time.perf_counter()
        for i, v in enumerate(values):
            run.step(v, 4 * i, i)
        timings.append((time.perf_counter() - start) / len(values))
    assert statistics.median(timings) < 25e-6
