"""``retrokit demo``: the benchmark on the bundled test cartridge, JERK against random.

It needs no ROM import: Dasher, retrokit's own Genesis game, ships in
``games/``. The command runs ``retrokit evaluate --benchmark dasher --agent jerk
--agent random`` (the same comparison, :mod:`retrokit.benchmark.comparison`)
on the test levels; prints the per-level table and the aggregates; and writes
each run's folder (episodes, summary, report, plots), the side-by-side report
and plot of the two agents' scores, and a GIF of JERK's best episode. The
output folder gets a new name if the given one is taken: nothing is replaced.
"""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

from retrokit.commands._common import add_evaluation_options
from retrokit.errors import FileConflictError
from retrokit.paths import ensure_folder

AGENTS = ("jerk", "random")


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``demo`` command."""
    parser = subparsers.add_parser(
        "demo",
        help="evaluate JERK against random on the bundled Dasher benchmark: table, report, plots and a GIF",
        description="Run the Dasher benchmark (no ROM import needed) with the paper's JERK agent and with random "
        "actions, with a progress bar per level (a line per level when the output is not a terminal); print the "
        "per-level scores and aggregates, and write each agent's run folder, a side-by-side report.md, "
        "scores.png and mean-learning-curve.png, and a GIF of JERK's best episode. It is `retrokit evaluate --benchmark dasher --agent jerk "
        "--agent random`.",
    )
    add_evaluation_options(parser, "processes (default: up to 2)")
    parser.add_argument("--out", type=Path, default=Path("retrokit-demo"), help="the output folder (default: retrokit-demo)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars or lines")
    parser.set_defaults(run=run)


def free_folder(path: Path) -> Path:
    """``path``, or ``path-1``, ``path-2``...: the first that does not exist or is an empty folder.

    Raises:
        FileSystemError: ``path`` is a file (checked before anything is played).
        FileConflictError: Every name is taken.
    """
    if path.exists() and not path.is_dir():
        ensure_folder(path, "for the demo's results")  # says what is wrong with it
    for n in range(10_000):
        candidate = path if n == 0 else path.with_name(f"{path.name}-{n}")
        if not candidate.exists() or (candidate.is_dir() and not any(candidate.iterdir())):
            return candidate
    raise FileConflictError(
        f"Expected a free folder name for {path}; found all 10000 taken. Delete some, or pass --out."
    )


def run(args: argparse.Namespace) -> int:
    """Evaluate both agents, print the table, write the comparison and the GIF."""
    from retrokit.benchmark.comparison import agent_folders, compare
    from retrokit.benchmark.definition import load_benchmark
    from retrokit.benchmark.evaluation import Evaluation, level_file_name
    from retrokit.commands.evaluate import print_build_hints, print_speed, print_table

    benchmark = load_benchmark("dasher")
    levels = benchmark.select(args.levels)
    out = free_folder(args.out)

    made: list[Evaluation] = []

    def make(agent: str, folder: Path) -> Evaluation:
        made.append(Evaluation(benchmark=benchmark, levels=levels, agent=agent, out=folder, budget=args.timesteps,
                               seed=args.seed, workers=args.workers, gif=agent == "jerk", progress=not args.no_progress))
        return made[-1]

    summaries = compare(make, list(AGENTS), out, announce=print)
    print_table(summaries)
    jerk, rand = summaries["jerk"].aggregate, summaries["random"].aggregate
    if jerk is not None and rand:
        print(f"JERK's aggregate is {jerk / rand:.2f}x random's.")
    folders = agent_folders(list(AGENTS))
    written = [f"{out / folders[agent]}/ (report.md, summary.json, plots)" for agent in AGENTS]
    written.append(f"{out / 'report.md'}, {out / 'scores.png'} and {out / 'mean-learning-curve.png'} "
                   "(the two agents side by side)")
    best = max(summaries["jerk"].levels.items(), key=lambda item: item[1].best or float("-inf"))[0]
    gif = out / folders["jerk"] / "gifs" / f"{level_file_name(best)}.gif"
    if gif.is_file():
        shutil.copyfile(gif, out / "jerk-best.gif")
        written.append(f"{out / 'jerk-best.gif'} (JERK's best episode, on {best})")
    print("wrote " + "\n      ".join(written))
    print_speed(made)  # as `retrokit evaluate` prints it: each agent's speed
    print_build_hints(levels)  # and how much faster a built core would make it
    return 0


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit demo                                   # the whole demo, into ./retrokit-demo",
    "retrokit demo --levels Zone1.Act1 --timesteps 2000 --out quick-demo",
]
