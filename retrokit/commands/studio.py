"""``retrokit studio [GAME] [--state S] [--port N] [--no-browser]``: the integration studio, in a browser."""

from __future__ import annotations

import argparse

DEFAULT_PORT = 8722
DEFAULT_GAME = "Dasher-Genesis"


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``studio`` command."""
    parser = subparsers.add_parser(
        "studio",
        help="integrate a game in your browser: play, states, movies, RAM search, fields, scenario, validate",
        description="Start the studio, a local web server, and open its page in your browser. It listens on "
        "127.0.0.1 only and prints its URL, with an access token in it, on one line: open that URL (the token "
        "is required). Ctrl-C stops it. Its JSON/WebSocket API, for scripts, is in `retrokit docs studio-api`.",
    )
    parser.add_argument("game", nargs="?", metavar="GAME",
                        help=f"the game, by name or folder (default: the game.yaml folder in the current "
                        f"directory, else {DEFAULT_GAME})")
    parser.add_argument("--state", help="the state to start from (default: the game's default state)")
    parser.add_argument("--port", type=int, default=DEFAULT_PORT,
                        help=f"the port to listen on (default: {DEFAULT_PORT}; 0: any free port)")
    parser.add_argument("--no-browser", action="store_true", help="print the URL but do not open a browser")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Serve the studio until Ctrl-C."""
    from pathlib import Path

    from retrokit.studio.server import serve

    game = args.game if args.game is not None else ("." if Path("game.yaml").is_file() else DEFAULT_GAME)
    serve(game, args.state, port=args.port, open_browser=not args.no_browser)
    return 0


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit studio Dasher-Genesis                      # opens the page in your browser",
    "retrokit studio Airstriker-Genesis --state Level1 --port 8800 --no-browser",
]
