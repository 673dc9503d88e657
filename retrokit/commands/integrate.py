"""``retrokit integrate GAME [--state NAME]... [--force]``: make and check a game's save states."""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``integrate`` command."""
    parser = subparsers.add_parser(
        "integrate",
        help="make a game's save states from the recipes in its game.yaml, and check existing ones",
        description="Play each state recipe of the game's game.yaml (under 'integrate') from power-on, "
        "write the state it reaches as <name>.state in the game's folder, and check a state file that is "
        "already there leads to the same RAM and screen. A state that differs is kept unless --force.",
    )
    parser.add_argument("game", help="the game's name, e.g. Dasher-Genesis")
    parser.add_argument("--state", action="append", metavar="NAME", help="only this state (repeatable)")
    parser.add_argument("--force", action="store_true", help="replace states that differ from their recipe")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Integrate the states; exit 1 if any differs from its recipe."""
    from retrokit.data.games import find_game
    from retrokit.data.integrate import integrate

    outcomes = integrate(find_game(args.game), args.state, force=args.force)
    width = max(len(o.name) for o in outcomes)
    for outcome in outcomes:
        print(f"{outcome.name:<{width}}  {outcome.status:<10}  {outcome.path}")
    differs = [o.name for o in outcomes if o.status in ("differs", "damaged")]
    if differs:
        print(f"{len(differs)} state(s) differ from their recipe or are damaged; rerun with --force to replace them.")
        return 1
    return 0
