"""``retrokit games [--imported] [PATTERN]``: the known games, their ROMs, scenarios and states."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from retrokit.commands._common import add_data_dir_option, rom_status

if TYPE_CHECKING:
    from retrokit.data.games import Game


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``games`` command."""
    parser = subparsers.add_parser(
        "games",
        help="list the known games, their states, and whether their ROM is available",
        description="List the known games with their states (the default one marked *), "
        "whether each game's ROM is available (bundled with the game, or imported), and whether "
        "each of its scenarios compiles ('ok', 'none', or 'refused:' and the names of those that do not). "
        "A game of a system nothing proves yet (no cartridge of ours, no game played against stable-retro: "
        "retrokit docs systems) is marked 'unproven'.",
    )
    parser.add_argument("pattern", nargs="?", metavar="PATTERN",
                        help="only games whose name matches this glob, or contains this text; a game's exact name shows that game only")
    parser.add_argument("--imported", action="store_true", help="only games whose ROM is available")
    add_data_dir_option(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """List the games."""
    from retrokit.data.games import list_games, normalize_name
    from retrokit.errors import GameNotFoundError, RetrokitError, did_you_mean

    # A game's full name (or its -v0 name) shows that game, not every name that contains it.
    exact = [g for g in list_games() if args.pattern is not None and g.name == normalize_name(args.pattern)]
    games = exact or list_games(args.pattern)
    if not games:
        names = [g.name for g in list_games()]
        raise GameNotFoundError(
            f"Expected a pattern matching some of the {len(names)} known games; found none matching "
            f"{args.pattern!r}. Try a shorter pattern, or run retrokit games to see them all."
            + did_you_mean(args.pattern, names)
        )
    width = max(len(g.name) for g in games)
    shown = available = refused = unproven = 0
    for game in games:
        try:
            status, _ = rom_status(game, args.data_dir)
        except RetrokitError as exc:
            status, line = "broken", f"{game.name:<{width}}  (cannot be read: {exc})"
        available += status in ("bundled", "imported")
        if args.imported and status not in ("bundled", "imported"):
            continue
        if status != "broken":
            try:
                states = ", ".join(s + ("*" if s == game.default_state else "") for s in game.states)
                broken = scenarios_refused(game)
                scenarios = "refused: " + ", ".join(broken) if broken else "ok" if game.scenarios else "none"
                line = f"{game.name:<{width}}  ROM {status:<8}  scenarios {scenarios}  states: {states or '(none)'}"
                refused += bool(broken)
                if not game.system.proven:  # nothing shows its RAM map, buttons or states are right
                    line += f"  [unproven: {game.system.name}]"
                    unproven += 1
            except RetrokitError as exc:
                line = f"{game.name:<{width}}  (cannot be read: {exc})"
        shown += 1
        print(line)
    print(f"{shown} game{'s' * (shown != 1)} shown; {available} of {len(games)} have their ROM"
          + (f"; {refused} shown {'has' if refused == 1 else 'have'} a scenario that does not compile" if refused else "")
          + (f"; {unproven} shown {'is' if unproven == 1 else 'are'} of a system nothing proves yet "
             "(retrokit docs systems)" if unproven else "")
          + ". Import ROMs with: retrokit import /path/to/your/roms")
    return 0


def scenarios_refused(game: Game) -> list[str]:
    """The names of the game's scenarios that do not load and compile (empty if all do, or it has none)."""
    from retrokit.dsl.scenario import load_scenario
    from retrokit.errors import RetrokitError

    fields = list(game.fields)
    refused = []
    for name, path in game.scenarios.items():
        try:
            load_scenario(path, fields)
        except RetrokitError:
            refused.append(name)
    return refused


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit games                     # every known game",
    "retrokit games 'Sonic*'            # only the games whose name matches",
    "retrokit games --imported          # only those whose ROM is here",
]
