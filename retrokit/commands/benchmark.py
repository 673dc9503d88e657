"""``retrokit benchmark new GAME``: write a benchmark file from a game's states, scenario and actions.

The file is what ``retrokit evaluate --benchmark FILE`` takes and ``retrokit
validate FILE`` checks; its levels, rules and budget are chosen as
:mod:`retrokit.benchmark.making` says, each choice named in a comment.
"""

from __future__ import annotations

import argparse

from retrokit.commands._common import add_force_option
from retrokit.errors import InvalidArgumentError


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``benchmark`` command and its ``new`` subcommand."""
    parser = subparsers.add_parser(
        "benchmark",
        help="write a benchmark file of a game (its levels, the protocol's rules, its scenario)",
        description="Make benchmark files for retrokit evaluate --benchmark FILE.",
    )
    commands = parser.add_subparsers(title="subcommands", metavar="SUBCOMMAND")
    new = commands.add_parser(
        "new",
        help="write a benchmark YAML of a game: its states as levels, the protocol's rules, its scenario",
        description="Write a benchmark file of GAME. Its states are the levels: states named alike but for their "
        "last number form a zone, whose last state is held out to test and the others trained on (a game whose "
        "states form no zone trains and tests on all); --train and --test choose instead. The env rules are the "
        "paper's protocol (4 frames a step, sticky frame skip 0.25, 4500 steps an episode), the budget its "
        "1,000,000 timesteps a level unless --budget; the scenario is the game's default (or --scenario), and its "
        "actions, if it lists some, are the agents' (action_type: filtered).",
    )
    new.add_argument("game", metavar="GAME", help="the game, e.g. Hopper-Nes")
    new.add_argument("--train", metavar="STATE,...", help="the states to train on (default: see above)")
    new.add_argument("--test", metavar="STATE,...", help="the states to test on (default: see above)")
    new.add_argument("--budget", metavar="N", help="timesteps per level (default: 1000000, the protocol's)")
    new.add_argument("--max-episode-steps", metavar="N", help="steps an episode lasts at most (default: 4500)")
    new.add_argument("--scenario", metavar="NAME", help="the game's scenario to play (default: its default one)")
    new.add_argument("--out", metavar="FILE", help="the file to write (default: GAME.yaml, lower case, here)")
    add_force_option(new, "replace an existing file", said_overwrite=False)
    new.set_defaults(run=_new)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """``retrokit benchmark`` alone: say which subcommands there are."""
    raise InvalidArgumentError("Expected a subcommand of benchmark: new; got none. See: retrokit benchmark --help")


def _number(text: str | None, what: str, default: int) -> int:
    if text is None:
        return default
    try:
        return int(text)
    except ValueError:
        raise InvalidArgumentError(f"Expected {what} as a whole number; got {text!r}.") from None


def _names(text: str | None) -> list[str] | None:
    return None if text is None else [name.strip() for name in text.split(",") if name.strip()]


def _new(args: argparse.Namespace) -> int:
    from retrokit.benchmark.making import PROTOCOL_BUDGET, benchmark_text, make_benchmark
    from retrokit.data.games import find_game
    from retrokit.envs.sonic import MAX_EPISODE_STEPS
    from retrokit.paths import atomic_write

    game = find_game(args.game)
    made = make_benchmark(
        game, _names(args.train), _names(args.test),
        budget=_number(args.budget, "--budget", PROTOCOL_BUDGET),
        max_episode_steps=_number(args.max_episode_steps, "--max-episode-steps", MAX_EPISODE_STEPS),
        scenario=args.scenario,
    )  # fmt: skip
    out = args.out or f"{game.name.lower()}.yaml"
    atomic_write(out, benchmark_text(made).encode(), overwrite=args.force)
    bench = made.benchmark
    print(f"Wrote the {bench.name} benchmark to {out}: train {', '.join(lv.state for lv in bench.train)}; "
          f"test {', '.join(lv.state for lv in bench.test)} ({made.split}); {bench.budget:,} timesteps a level.")  # fmt: skip
    return 0


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit benchmark new Hopper-Nes                   # writes hopper-nes.yaml",
    "retrokit benchmark new Dasher-Genesis --train Zone1.Act1 --test Zone1.Act2 --budget 20000 --out mine.yaml",
]
