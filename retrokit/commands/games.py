"""``retrokit games [--imported] [PATTERN]``: the known games, their states, and their ROMs."""

from __future__ import annotations

import argparse

from retrokit.commands._common import add_data_dir_option, rom_status


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``games`` command."""
    parser = subparsers.add_parser(
        "games",
        help="list the known games, their states, and whether their ROM is available",
        description="List the known games with their states (the default one marked *) and "
        "whether each game's ROM is available (bundled with the game, or imported).",
    )
    parser.add_argument("pattern", nargs="?", metavar="PATTERN",
                        help="only games whose name matches this glob, or contains this text")
    parser.add_argument("--imported", action="store_true", help="only games whose ROM is available")
    add_data_dir_option(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """List the games."""
    from retrokit.data.games import list_games
    from retrokit.errors import GameNotFoundError, RetrokitError, did_you_mean

    games = list_games(args.pattern)
    if not games:
        names = [g.name for g in list_games()]
        raise GameNotFoundError(
            f"Expected a pattern matching some of the {len(names)} known games; found none matching "
            f"{args.pattern!r}. Try a shorter pattern, or run retrokit games to see them all."
            + did_you_mean(args.pattern, names)
        )
    width = max(len(g.name) for g in games)
    shown = available = 0
    for game in games:
        try:
            status, _ = rom_status(game, args.data_dir)
            states = ", ".join(s + ("*" if s == game.default_state else "") for s in game.states)
            line = f"{game.name:<{width}}  ROM {status:<8}  states: {states or '(none)'}"
        except RetrokitError as exc:
            status, line = "broken", f"{game.name:<{width}}  (cannot be read: {exc})"
        available += status in ("bundled", "imported")
        if args.imported and status not in ("bundled", "imported"):
            continue
        shown += 1
        print(line)
    print(f"{shown} game{'s' * (shown != 1)} shown; {available} of {len(games)} have their ROM. "
          "Import ROMs with: retrokit import /path/to/your/roms")
    return 0
