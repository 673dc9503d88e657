"""``retrokit evaluate``: the benchmark protocol, played by an agent, reported beside the paper.

Each level is played for the benchmark's budget of timesteps; a level's score
is the mean total reward of its episodes, the aggregate the mean of the level
scores. See docs/evaluate.md.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from retrokit.commands._common import add_evaluation_options

EXAMPLES = [
    "retrokit evaluate --benchmark dasher --agent jerk --out runs/jerk",
    "retrokit evaluate --benchmark sonic --list            # the benchmark's levels",
    "retrokit evaluate --agent my_agents:make_agent --levels all --workers 2 --out runs/mine --gif",
    "retrokit evaluate --out runs/mine --resume             # continue an interrupted run",
]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``evaluate`` command."""
    parser = subparsers.add_parser(
        "evaluate",
        help="run a benchmark (sonic, dasher or a YAML file) with an agent; write scores, a report and plots",
        description="Play each level of a benchmark for its budget of timesteps with an agent, with a progress bar "
        "per level, and write episodes.jsonl, summary.json, summary.csv, report.md (beside the paper's scores) and "
        "PNG plots into --out.",
    )
    parser.add_argument("--benchmark", default="dasher", help="sonic, dasher, or a benchmark YAML file (default: dasher)")
    parser.add_argument("--agent", default="jerk", help="random, jerk, or MODULE:CALLABLE (default: jerk)")
    add_evaluation_options(parser, "processes (or Ray CPUs) sharing the levels (default: up to 2)")
    parser.add_argument("--backend", choices=("local", "ray"), default="local", help="local processes, or Ray")
    parser.add_argument("--ray-address", default=None, help="an existing Ray cluster (default: start a local Ray)")
    parser.add_argument("--out", type=Path, default=None, metavar="DIR", help="the run folder (required, except with --list)")
    parser.add_argument("--resume", action="store_true", help="continue the interrupted evaluation in --out")
    parser.add_argument("--gif", action="store_true", help="save a GIF of each level's best episode in --out/gifs")
    parser.add_argument("--list", action="store_true", help="list the benchmark's levels and stop")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Evaluate, then print the per-level table and the aggregate."""
    from retrokit.benchmark.definition import load_benchmark
    from retrokit.benchmark.evaluation import Evaluation, evaluate
    from retrokit.errors import InvalidArgumentError

    benchmark = load_benchmark(args.benchmark)
    if args.list:
        for split, levels in (("test", benchmark.test), ("train", benchmark.train)):
            for level in levels:
                print(f"{split:5}  {level.name}")
        return 0
    if args.out is None:
        raise InvalidArgumentError("Expected --out DIR, the folder for the results; got none.")
    evaluation = Evaluation(
        benchmark=benchmark, levels=benchmark.select(args.levels), agent=args.agent, out=args.out,
        budget=args.timesteps, seed=args.seed, workers=args.workers, backend=args.backend,
        ray_address=args.ray_address, resume=args.resume, gif=args.gif, progress=not args.no_progress,
    )
    try:
        summary = evaluate(evaluation)
    except KeyboardInterrupt:
        print(f"retrokit: interrupted; the finished levels are in {args.out}: add --resume to the same command "
              "to finish the rest", file=__import__("sys").stderr)
        return 130
    print_table({args.agent: summary})
    print(f"wrote {args.out}/: episodes.jsonl, summary.json, summary.csv, report.md"
          + (", learning-curves.png, scores.png" if (args.out / "scores.png").exists() else ""))
    return 0


def print_table(summaries: dict[str, dict]) -> None:
    """Print each level's score for each agent, and the aggregates."""
    levels = list(dict.fromkeys(level for s in summaries.values() for level in s["levels"]))
    width = max([len("aggregate"), *map(len, levels)])
    print("\n" + "level".ljust(width) + "".join(f"  {agent:>12}" for agent in summaries))
    for level in levels:
        cells = [s["levels"].get(level, {}).get("mean_score") for s in summaries.values()]
        print(level.ljust(width) + "".join(f"  {'-' if c is None else f'{c:12.1f}':>12}" for c in cells))
    aggregates = [s["aggregate"] for s in summaries.values()]
    print("aggregate".ljust(width) + "".join(f"  {'-' if a is None else f'{a:12.1f}':>12}" for a in aggregates))
