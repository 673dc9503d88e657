"""``retrokit evaluate``: the benchmark protocol, played by one agent or several, reported beside the paper.

Each level is played for the benchmark's budget of timesteps, in a worker
process of its own; a level's score is the mean total reward of its episodes,
the aggregate the mean of the level scores. With several ``--agent``, each
agent's run goes into ``OUT/<agent>/`` and ``OUT/report.md`` sets them side by
side. See docs/evaluate.md.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from retrokit.commands._common import add_backend_options, add_evaluation_options, add_learning_options

AGENT_NOTE = """\
An agent is random, jerk, ppo, rainbow, or MODULE:CALLABLE (an importable module or a .py file), a callable
    agent(env: gymnasium.Env, budget: int, seed: int) -> None
that loops over env.reset() and env.step(action) until step() raises BudgetSpent (the runner catches it).
ppo and rainbow learn during each level's budget (the paper's PPO and Rainbow); with --init DIR they start
from a policy that `retrokit train` made (Joint PPO, Joint Rainbow), and with --no-learn only play it (the
zero-shot score). They need
the extra retrokit-rl[train]. The Ray backend is an extra: pip install 'retrokit-rl[ray]'.
"""

EXAMPLES = [
    "retrokit evaluate --benchmark dasher --agent jerk --out runs/jerk",
    "retrokit evaluate --benchmark dasher --agent jerk --agent random --timesteps 2000 --out runs/both",
    "retrokit evaluate --agent my_agents.py:ppo --levels all --workers 2 --out runs/mine --gif",
    "retrokit evaluate --out runs/mine --resume             # continue an interrupted run",
    "retrokit evaluate --benchmark mine.yaml --agent random --stall-timeout 120 --out runs/mine",
    "retrokit evaluate --benchmark sonic --agent jerk --backend ray --ray-address auto --out runs/sonic",
    "retrokit evaluate --benchmark sonic --list            # the benchmark's levels",
    "retrokit evaluate --agent ppo --agent-config quick --levels Zone1.Act2 --timesteps 120000 --out runs/ppo",
    "retrokit evaluate --agent ppo --init runs/joint --out runs/joint-ppo      # Joint PPO: fine-tune a trained policy",
    "retrokit evaluate --agent ppo --init runs/joint --no-learn --out runs/zero-shot",
    "retrokit evaluate --agent rainbow --agent-config quick --levels Zone1.Act2 --timesteps 120000 --out runs/rainbow",
]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``evaluate`` command."""
    from retrokit.benchmark.watchdog import DEFAULT_STALL_SECONDS

    parser = subparsers.add_parser(
        "evaluate",
        help="run a benchmark (sonic, dasher, trekker, ... or a YAML file) with one agent or several; write scores, a report and plots",
        description="Play each level of a benchmark for its budget of timesteps with an agent, each level in a worker "
        "process, and write episodes.jsonl, summary.json, summary.csv, report.md (beside the paper's scores) and "
        "PNG plots into --out. Progress shows as a bar per level on a terminal, else as a line per finished level. "
        "With several --agent, each runs into OUT/<agent>/ and OUT/report.md, OUT/scores.png and "
        "OUT/mean-learning-curve.png compare them.",
        epilog=AGENT_NOTE,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--benchmark", default="dasher", help="sonic, dasher, or another cartridge's benchmark (hopper-nes, hopper-sms, hopper-gg, trekker, trekker-color, skipper-pce, skipper-snes: tools/cartridges.yaml), or a benchmark YAML file (default: dasher)")
    parser.add_argument("--agent", action="append", default=None, metavar="AGENT",
                        help="random, jerk, ppo, rainbow, or MODULE:CALLABLE; repeat it to compare agents (default: jerk)")
    add_learning_options(parser)
    parser.add_argument("--no-learn", action="store_true",
                        help="play the --init policy without learning (its zero-shot score, the paper's Figure 4)")
    add_evaluation_options(parser, "processes (or Ray CPUs) sharing the levels (default: up to 2)")
    parser.add_argument("--stall-timeout", type=float, default=DEFAULT_STALL_SECONDS, metavar="SECONDS",
                        help="stop a level whose agent takes no timestep for this long, and fail it "
                        f"(default: {DEFAULT_STALL_SECONDS:g})")
    add_backend_options(parser, "local processes")
    parser.add_argument("--out", type=Path, default=None, metavar="DIR", help="the run folder (required, except with --list)")
    parser.add_argument("--resume", action="store_true", help="continue the interrupted evaluation in --out")
    parser.add_argument("--gif", action="store_true", help="save a GIF of each level's best episode in --out/gifs")
    parser.add_argument("--list", action="store_true", help="list the benchmark's levels and stop")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars or lines")
    # None: not given. A --resume takes what was not given from the run folder; else the defaults the help names.
    parser.set_defaults(run=run, benchmark=None, levels=None, seed=None)


def _resumed(args: argparse.Namespace) -> None:
    """Fill the options not given from the run folder's ``run.json`` (``--out DIR --resume`` alone continues a run).

    A comparison's folder holds one run folder per agent: their settings are the same but the agent, so the
    other options come from the first, and ``--agent`` must name the agents.

    Raises:
        RunFolderError: The folder holds no evaluation, or a damaged one.
        InvalidArgumentError: A comparison's folder, and no --agent.
    """
    from retrokit.benchmark.definition import benchmark_from_data
    from retrokit.benchmark.rundir import RUN_FILE, read_run_file
    from retrokit.errors import InvalidArgumentError, RunFolderError

    folder = args.out
    if not os.path.lexists(folder / RUN_FILE):
        agents = sorted(p.parent for p in folder.glob(f"*/{RUN_FILE}"))
        if agents and not args.agent:
            raise InvalidArgumentError(
                f"Expected --agent for each agent of the comparison in {str(folder)!r} (its folders: "
                f"{', '.join(p.name for p in agents)}); found none. Pass them as the interrupted command did."
            )
        folder = agents[0] if agents else folder
    settings = read_run_file(folder)["settings"]

    def fail(problem: str) -> RunFolderError:
        return RunFolderError(f"Expected {folder / RUN_FILE}'s benchmark to resume, but {problem}; start in a new --out.")

    if args.benchmark is None:
        args.benchmark = benchmark_from_data(settings.get("benchmark"), fail, "benchmark")
    if not args.agent and isinstance(settings.get("agent"), str):
        args.agent = [settings["agent"]]
    if args.levels is None and isinstance(settings.get("levels"), list):
        args.levels = ",".join(map(str, settings["levels"]))
    for option, key in (("timesteps", "budget"), ("seed", "seed")):
        if getattr(args, option) is None and isinstance(settings.get(key), int):
            setattr(args, option, settings[key])
    setup = settings.get("agent_setup")
    if isinstance(setup, dict):  # a learning agent's run: its config, its start policy, whether it learned
        config, init = setup.get("config"), setup.get("init")
        if args.agent_config is None and isinstance(config, dict) and isinstance(config.get("name"), str):
            args.agent_config = config["name"]  # a shipped config's name or the user's file, read (and checked) again
        if args.init is None and isinstance(init, dict) and isinstance(init.get("policy"), str):
            args.init = init["policy"]
        if setup.get("learn") is False:
            args.no_learn = True


def run(args: argparse.Namespace) -> int:
    """Evaluate, then print the per-level table and the aggregate."""
    from retrokit.benchmark.comparison import compare
    from retrokit.benchmark.definition import Benchmark, load_benchmark
    from retrokit.benchmark.evaluation import Evaluation, evaluate
    from retrokit.errors import InvalidArgumentError
    from retrokit.learning.algorithms import is_learning_agent
    from retrokit.learning.setup import prepare

    if args.resume and args.out is not None:
        _resumed(args)
    benchmark = load_benchmark(args.benchmark or "dasher") if not isinstance(args.benchmark, Benchmark) else args.benchmark
    levels_spec, seed = args.levels or "test", args.seed or 0
    if args.list:
        for split, levels in (("test", benchmark.test), ("train", benchmark.train)):
            for level in levels:
                print(f"{split:5}  {level.name}")
        return 0
    if args.out is None:
        raise InvalidArgumentError("Expected --out DIR, the folder for the results; got none.")
    agents = args.agent or ["jerk"]
    levels = benchmark.select(levels_spec)
    made: list[Evaluation] = []

    def make(agent: str, out: Path) -> Evaluation:
        # Each learning agent gets the learning options; given to no learning agent at all, they are refused.
        setup = prepare(agent, benchmark, args.agent_config, args.init, learn=not args.no_learn) \
            if is_learning_agent(agent) or not any(map(is_learning_agent, agents)) else None
        made.append(Evaluation(
            benchmark=benchmark, levels=levels, agent=agent, out=out, budget=args.timesteps, seed=seed,
            workers=args.workers, backend=args.backend, ray_address=args.ray_address, resume=args.resume,
            gif=args.gif, progress=not args.no_progress, stall_timeout=args.stall_timeout, setup=setup,
        ))
        return made[-1]

    try:
        if len(agents) == 1:
            summaries = {agents[0]: evaluate(make(agents[0], args.out))}
        else:
            summaries = compare(make, agents, args.out, resume=args.resume, announce=print)
    except KeyboardInterrupt:
        print(f"retrokit: interrupted; the finished levels are in {args.out}: add --resume to the same command "
              "to finish the rest", file=sys.stderr)
        return 130
    print_table(summaries)
    print(f"wrote {args.out}/: " + ("episodes.jsonl, summary.json, summary.csv, report.md, learning-curves.png, "
                                    "scores.png, mean-learning-curve.png" if len(agents) == 1 else
                                    "report.md, scores.png, mean-learning-curve.png, and a run folder per agent"))
    print_speed(made)
    print_build_hints(levels)
    return 0


def print_build_hints(levels: list) -> None:  # retrokit.benchmark.definition.Level
    """Say, on stderr, how much faster the levels' systems would run on a core ``retrokit build-core`` makes."""
    from retrokit.data.games import find_game
    from retrokit.host.buildhint import build_hints

    for line in build_hints(find_game(level.game).system for level in levels):
        print(line, file=sys.stderr)  # stdout is the results, the same on every machine


def print_speed(made: list) -> None:  # retrokit.benchmark.evaluation.Evaluation
    """Print each evaluation's speed and the Sonic protocol's estimated time, named by agent if several."""
    from retrokit.benchmark.speed import estimate_line

    for evaluation in made:  # on stderr, beside the progress: stdout is the results, the same on every machine
        speed = evaluation.speed()
        if speed is not None:
            line = estimate_line(speed, sonic=evaluation.benchmark.name == "sonic")
            print(("" if len(made) == 1 else f"{evaluation.agent}: ") + line, file=sys.stderr)


def print_table(summaries: dict) -> None:  # agent -> retrokit.benchmark.scores.Summary
    """Print each level's score for each agent, and the aggregates."""
    levels = list(dict.fromkeys(level for s in summaries.values() for level in s.levels))
    width = max([len("aggregate"), *map(len, levels)])
    print("\n" + "level".ljust(width) + "".join(f"  {agent:>12}" for agent in summaries))
    for level in levels:
        cells = [s.levels[level].mean_score if level in s.levels else None for s in summaries.values()]
        print(level.ljust(width) + "".join(f"  {'-' if c is None else f'{c:12.1f}':>12}" for c in cells))
    aggregates = [s.aggregate for s in summaries.values()]
    print("aggregate".ljust(width) + "".join(f"  {'-' if a is None else f'{a:12.1f}':>12}" for a in aggregates))
