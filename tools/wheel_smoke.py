#!/usr/bin/env python3
"""Smoke test of an installed retrokit, run by CI from an empty folder in a fresh venv.

It checks what a user of ``pip install retrokit-rl`` gets, with no checkout on
the path: the bundled games and test cartridge, the lazy public names, the
envs on the real emulator, the Sonic preset up to the missing-ROM error, and
the guides that ``retrokit docs`` prints.
Exits non-zero, naming the check, when one fails.
"""

from __future__ import annotations

import sys
from pathlib import Path


def main() -> int:
    import numpy as np

    import retrokit
    from retrokit.errors import RomNotFoundError

    package = Path(retrokit.__file__).resolve().parent
    if Path.cwd() in package.parents or (Path.cwd() / "retrokit").is_dir():
        return fail("run from a folder with no retrokit checkout in it")
    checks = {
        "bundled Dasher": lambda: (package / "_games" / "Dasher-Genesis" / "game.yaml").is_file(),
        "47 train levels": lambda: len(retrokit.sonic.train_levels()) == 47,
        "11 test levels": lambda: len(retrokit.sonic.test_levels()) == 11,
        "multiplayer": lambda: callable(retrokit.multiplayer.parallel_env),
        "movie": lambda: callable(retrokit.movie.play),
    }
    for name, check in checks.items():
        if not check():
            return fail(name)

    env = retrokit.make("Dasher-Genesis", frameskip=4, max_episode_steps=50)
    obs, info = env.reset(seed=0)
    total = 0.0
    for _ in range(50):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        total += reward
        if terminated or truncated:
            break
    env.close()
    if obs.shape != (224, 320, 3) or "p1_x" not in info:
        return fail(f"Dasher env: observation {obs.shape}, info keys {sorted(info)[:5]}")

    pz = retrokit.multiplayer.parallel_env("Dasher-Genesis")
    observations, _ = pz.reset(seed=0)
    pz.step({agent: pz.action_space(agent).sample() for agent in pz.agents})
    pz.close()
    if len(observations) != 2:
        return fail("two-player env")

    try:
        retrokit.sonic.make("SonicTheHedgehog-Genesis", "GreenHillZone.Act1")
    except RomNotFoundError as exc:
        if "retrokit import" not in str(exc):
            return fail(f"Sonic's missing-ROM error names no fix: {exc}")
    else:
        return fail("Sonic made without its ROM")
    problem = check_docs(package) or check_paper(package)
    if problem:
        return fail(problem)
    print(f"wheel smoke test: ok ({package}, Dasher reward {total:.1f}, {np.__version__=})")
    return 0


def check_docs(package: Path) -> str:
    """What is wrong with ``retrokit docs`` run from the installed command, or ``""``: the guides ship in the wheel."""
    import subprocess

    command = Path(sys.executable).with_name("retrokit")
    listing = subprocess.run([command, "docs"], capture_output=True, text=True, check=False)
    guide = subprocess.run([command, "docs", "integrate"], capture_output=True, text=True, check=False)
    typo = subprocess.run([command, "docs", "integrat"], capture_output=True, text=True, check=False)
    if not (package / "_docs" / "integrate.md").is_file():
        return "the guides (docs/*.md) are not in the wheel"
    if listing.returncode != 0 or not listing.stdout.startswith("architecture ") or "scenarios" not in listing.stdout:
        return f"retrokit docs listed: {listing.stdout[:200]!r} {listing.stderr[-200:]!r}"
    if guide.returncode != 0 or guide.stdout != (package / "_docs" / "integrate.md").read_text(encoding="utf-8"):
        return f"retrokit docs integrate printed: {guide.stdout[:100]!r} {guide.stderr[-200:]!r}"
    if typo.returncode != 2 or "Did you mean 'integrate'?" not in typo.stderr:
        return f"retrokit docs integrat said: {typo.stderr[-200:]!r}"
    return ""


def check_paper(package: Path) -> str:
    """What is wrong with the paper's scores in a report of the installed retrokit, or ``""``: they ship in the wheel.

    No Sonic ROM is here, so the report is of JERK's episodes as if played on the paper's 11 test levels.
    """
    import os

    import retrokit
    from retrokit.benchmark.monitor import Episode
    from retrokit.benchmark.paper import PAPER_ENV, load_paper
    from retrokit.benchmark.report import render_report
    from retrokit.benchmark.rundir import FinishedLevel
    from retrokit.benchmark.scores import summarize

    os.environ.pop(PAPER_ENV, None)  # retrokit's own copy, as a user has it
    paper = load_paper()
    if paper is None or package not in paper.path.parents or not (paper.path.parent / "README.md").is_file():
        return f"the paper's scores are not in the wheel: {paper and paper.path}"
    levels = [f"{game}/{state}" for game, state in retrokit.sonic.test_levels()]
    settings = {"benchmark": {"name": "sonic"}, "agent": "jerk", "seed": 0, "budget": 1000, "levels": levels}
    summary = summarize(settings, {level: FinishedLevel(1000, 1) for level in levels},
                        {level: [Episode(1, 900, 1000.0, 900, 1.0)] for level in levels})
    text = render_report(summary, paper, plots=[])
    wanted = ["beside the paper's Table 3 (JERK)", "| JERK (paper) | 1,904.0 | 21.9 | 2,306.8 | 74.0 |",
              "| Joint PPO (paper) | 3,127.9 | 116.9 | 3,926.3 | 78.1 |", "| **jerk** (this run) | **1,000.0** |",
              "| 3,702.1 | 4,862.2 | -2,702.1 |"]  # GreenHillZone.Act2: the paper's JERK score and final score
    missing = [line for line in wanted if line not in text]
    return f"the report lacks the paper's {missing}" if missing else ""


def fail(what: str) -> int:
    print(f"wheel smoke test failed: {what}", file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main())
