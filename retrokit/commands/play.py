"""``retrokit play GAME [--state S]``: play in a window; save states and record movies on keys."""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``play`` command."""
    parser = subparsers.add_parser(
        "play",
        help="play a game in a window (pygame); F5 saves a state, F9 starts and stops a movie",
        description="Play a game from the keyboard: arrows, Z X C (A B C), Enter (START), Tab (MODE/SELECT), "
        "A S D (X Y Z). F5 saves the current state as NAME.state, F9 starts recording a movie and F9 again "
        "writes it to movies/NAME-NNNNNN.bk2, Escape quits. Files go to your data folder's games/<Game> "
        "(which extends the shipped game) or --out. See retrokit docs integrate.",
    )
    parser.add_argument("game", help="the game, e.g. Dasher-Genesis")
    parser.add_argument("--state", help="the state to start from (default: the game's)")
    parser.add_argument("--name", default="Play", help="the name of saved states and movies (default: Play)")
    parser.add_argument("--out", metavar="DIR", help="write states and movies into DIR instead of your data folder")
    parser.add_argument("--scale", type=int, default=2, help="window pixels per console pixel (default: 2)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Open the window and play until quit."""
    from pathlib import Path

    from retrokit.data.games import find_game
    from retrokit.data.integrate import target_folder
    from retrokit.envs.play import PlaySession

    game = find_game(args.game)
    # What only the user can fix comes first: someone without pygame should not install it only to learn
    # that the ROM is missing or the state unknown (the session needs pygame before it starts the game).
    game.require_rom()
    if args.state is not None:
        game.state_path(args.state)
    folder = Path(args.out) if args.out else target_folder(game)
    session = PlaySession(game, args.state, folder, name=args.name, scale=args.scale)
    try:
        session.run()
    finally:
        session.close()
    print(f"{len(session.saved)} state(s) and {len(session.movies)} movie(s) saved in {folder}")
    return 0


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit play Dasher-Genesis                        # F5 saves a state, F9 records a movie",
    "retrokit play Airstriker-Genesis --state Level1 --name Mine --scale 3",
]
