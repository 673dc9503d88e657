"""``retrokit validate [GAME ...] [--all] [--json FILE]``: check game integrations end to end."""

from __future__ import annotations

import argparse
import sys


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``validate`` command."""
    parser = subparsers.add_parser(
        "validate",
        help="check games: data files, fields, states, scenarios (smoke runs) and solution movies",
        description="Check each game's integration: game.yaml and scenarios against the JSON Schemas, fields "
        "inside the system's RAM, every state (loaded in a child process, so a corrupt one cannot stop the run), "
        "every scenario (compiled, tables covering the states, a deterministic smoke run on every state) and "
        "the solution movies in movies/. Without a game's ROM, what needs it is skipped and the report says so. "
        "Prints one table per game and a summary; exits with status 1 if any check failed.",
    )
    parser.add_argument("games", nargs="*", metavar="GAME",
                        help="game names or game folders (default: the game.yaml folder in the current directory), "
                        "or benchmark files (FILE.yaml: its shape, levels and ROMs, and every level's env starting)")
    parser.add_argument("--all", action="store_true",
                        help="every game retrokit ships or you made: each game `retrokit games` lists whose first "
                        "folder is not the stable-retro wheel's (the repository's games/, RETROKIT_GAMES' folders "
                        "and the user's data folder). The wheel's own 1000 or so integrations, mostly without "
                        "their ROM, are left out: name them as GAME to check them. The run's first line lists the "
                        "games --all chose")
    parser.add_argument("--json", metavar="FILE", help="also write every result to this JSON file")
    parser.add_argument("--frames", type=int, default=None, metavar="N",
                        help="frames of scripted random play per state and scenario (default: 600)")
    parser.add_argument("--quiet", "-q", action="store_true", help="print only failures, warnings and skips")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Check the games; print a table per game and a summary; exit 1 on any failure."""
    from pathlib import Path

    from tqdm import tqdm

    from retrokit.benchmark.progress import is_terminal
    from retrokit.errors import InvalidArgumentError
    from retrokit.testing import STAGES, check_game
    from retrokit.testing.report import PASS, GameReport, render, summary, write_json

    if args.frames is not None and args.frames < 1:
        raise InvalidArgumentError(f"Expected --frames of 1 or more, got {args.frames}.")
    targets = list(args.games)
    if args.all:
        from retrokit.data.games import list_games

        own = own_games()
        everyone = len(list_games())
        print(f"--all: {len(own)} of the {everyone} games retrokit games lists, those not from the stable-retro "
              f"wheel (name one of the others to check it): {', '.join(own) or '(none)'}")
        targets += own
    if not targets:
        if not Path("game.yaml").is_file():
            raise InvalidArgumentError(
                "Expected game names, --all, or a game.yaml in the current directory; found none. "
                "Example: retrokit validate Dasher-Genesis"
            )
        targets = ["."]
    from retrokit.benchmark.making import is_benchmark_file

    benchmarks = [t for t in targets if is_benchmark_file(t)]
    targets = [t for t in targets if t not in benchmarks]
    checked = [_check_benchmark_file(path) for path in benchmarks]
    if not targets:
        return 0 if all(checked) else 1
    reports: list[GameReport] = []
    # A bar redraws in place, which only a terminal shows: in a pipe or a log, one line per stage instead.
    bars = is_terminal()
    with tqdm(total=len(targets) * len(STAGES), unit="stage", leave=False, disable=not bars) as bar:
        for target in targets:
            started = [0]  # stages of this game begun; the bar counts those finished

            def step(stage: str, detail: str, name: str = str(target), started: list[int] = started) -> None:
                bar.set_description(f"{name}: {detail or stage}")
                if not detail:  # a stage starts (so the one before it is done); details only say where it is
                    bar.update(1 if started[0] else 0)
                    started[0] += 1
                    if not bars and not args.quiet:
                        print(f"{name}: {stage} ({started[0]}/{len(STAGES)})", file=sys.stderr, flush=True)

            reports.append(check_game(target, frames=args.frames, progress=step))
            bar.update(len(STAGES) - max(started[0] - 1, 0))  # the last stage, and any a broken game skipped
    for report in reports:
        if args.quiet:
            shown = GameReport(report.game, [r for r in report.results if r.status != PASS])
            print(render(shown) if shown.results else f"{report.game}: all {len(report.results)} checks passed")
        else:
            print(render(report))
        print()
    print(summary(reports))
    if args.json:
        write_json(args.json, reports)
        print(f"wrote every result to {args.json}")
    return 0 if all(r.passed for r in reports) and all(checked) else 1


def _check_benchmark_file(path: str) -> bool:
    """Check a benchmark file; print what was found, in a line per problem; return whether it passed."""
    from retrokit.benchmark.definition import read_benchmark
    from retrokit.benchmark.making import check_benchmark
    from retrokit.errors import RetrokitError

    try:
        problems = check_benchmark(path)
    except RetrokitError as exc:
        print(f"{path}: FAIL: {exc}")
        return False
    bench = read_benchmark(path)
    print(f"{path}: the {bench.name} benchmark, {len(bench.train)} level(s) to train and {len(bench.test)} to test, "
          f"{bench.budget:,} timesteps a level: " + ("every level starts: ok" if not problems else "FAIL"))  # fmt: skip
    for problem in problems:
        print(f"  FAIL: {problem}")
    return not problems


def own_games() -> list[str]:
    """The games whose first folder is not the stable-retro wheel's: the ones this project and its users made."""
    from retrokit import paths
    from retrokit.data.games import list_games

    wheel = paths.wheel_dir()
    return [g.name for g in list_games() if wheel is None or not g.folders[0].is_relative_to(wheel)]


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit validate Dasher-Genesis                    # one game, by name",
    "retrokit validate games/MyGame-Genesis --json report.json",
    "retrokit validate --all --quiet                     # every game not from the wheel, failures only",
    "retrokit validate hopper-nes.yaml                   # a benchmark file: its levels start",
]
