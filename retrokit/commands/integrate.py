"""``retrokit integrate [GAME] STATE``: make save states from recipes or movies, into the user's data folder."""

from __future__ import annotations

import argparse
from pathlib import Path


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``integrate`` command."""
    parser = subparsers.add_parser(
        "integrate",
        help="make save states from the recipes in game.yaml, or from a movie, into your data folder",
        description="Make save states. 'retrokit integrate Zone1.Act1' makes the state of that name of the one "
        "known game that has it (else of the game.yaml in the current directory); 'retrokit integrate GAME "
        "[STATE]' names the game (all its recipes without STATE). A recipe is played from power-on; with "
        "--movie, the state is the one the movie reaches. States are written to your data folder "
        "($RETROKIT_DATA/games/<Game>, else $XDG_DATA_HOME/retrokit/games/<Game>), which extends the shipped "
        "game, or to --out; never into the installed package. A state already there that leads to the same "
        "RAM and screen is left alone; one that differs is kept unless --force. Format: retrokit docs integrate.",
    )
    parser.add_argument("names", nargs="+", metavar="NAME",
                        help="STATE, GAME, or GAME STATE (e.g. Zone1.Act1, Dasher-Genesis, Dasher-Genesis Zone1.Act1)")
    parser.add_argument("--state", action="append", metavar="NAME", help="only this state (repeatable; with GAME)")
    parser.add_argument("--movie", metavar="FILE.bk2", help="make the state the movie reaches instead of a recipe's")
    parser.add_argument("--frame", type=int, metavar="N", help="with --movie: the state after N frames (default: all)")
    parser.add_argument("--out", metavar="DIR", help="write the states into DIR instead of your data folder")
    parser.add_argument("--force", action="store_true", help="replace states that differ from what was made")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Integrate the states; exit 1 if any differs from what was made."""
    from retrokit.data.integrate import integrate, place_state, target_folder
    from retrokit.errors import InvalidArgumentError, shell_word
    from retrokit.movie.playback import state_from_movie

    if len(args.names) > 2:
        raise InvalidArgumentError(
            f"Expected STATE, GAME, or GAME STATE; found {len(args.names)} names: {' '.join(args.names)}."
        )
    if args.frame is not None and not args.movie:
        raise InvalidArgumentError("Expected --frame only with --movie FILE.bk2; found it alone.")
    if args.state and args.movie:
        raise InvalidArgumentError(
            f"Expected --state or --movie, not both; found --state {args.state[0]} with --movie {args.movie}. "
            f"To make a state from the movie, name it: retrokit integrate [GAME] NAME --movie {shell_word(args.movie)}"
        )
    out = Path(args.out) if args.out else None
    if args.movie:
        game, name = _movie_target(args.names, args.movie)
        state = state_from_movie(game, args.movie, args.frame)
        outcomes = [place_state(game, name, state, out or target_folder(game), force=args.force)]
    else:
        game, names = resolve(*args.names)
        if args.state:
            names = [*(names or []), *args.state]
        outcomes = integrate(game, names, force=args.force, out=out)
    width = max(len(o.name) for o in outcomes)
    for outcome in outcomes:
        print(f"{outcome.name:<{width}}  {outcome.status:<10}  {outcome.path}")
    differs = [o.name for o in outcomes if o.status in ("differs", "damaged")]
    if differs:
        print(f"{len(differs)} state(s) differ from what was made or are damaged; rerun with --force to replace them.")
        return 1
    return 0


def _movie_target(names: list[str], movie: str):  # -> (Game, state name)
    """The game and state name of ``integrate [GAME] NAME --movie FILE``: the game defaults to the movie's."""
    from retrokit.data.games import find_game
    from retrokit.data.names import check_state_name
    from retrokit.movie import read_bk2

    check_state_name(names[-1])  # before the movie is replayed: the name becomes a file name
    if len(names) == 2:
        return find_game(names[0]), names[1]
    return find_game(read_bk2(movie).game), names[0]


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit integrate Dasher-Genesis                   # every state recipe of the game",
    "retrokit integrate Dasher-Genesis Zone1.Act1 --force",
    "retrokit integrate Dasher-Genesis Mine --movie Mine-000000.bk2 --frame 600",
]


def resolve(first: str, second: str | None = None, *, cwd: Path | None = None):  # -> (Game, list[str] | None)
    """Which game and states ``retrokit integrate FIRST [SECOND]`` means.

    ``GAME STATE`` is that state of that game; ``GAME`` alone is all its recipes.
    A lone ``STATE`` belongs to the game whose game.yaml is in ``cwd`` (run
    inside a game's folder, as docs/integrate.md shows), else to the one known
    game that has a state file or a recipe of that name.

    Raises:
        UnknownNameError: ``cwd`` holds no game.yaml, and several games or none have that state.
    """
    from retrokit.data.games import find_game, list_games, normalize_name
    from retrokit.data.integrate import games_with_state
    from retrokit.errors import GameNotFoundError, UnknownNameError, did_you_mean

    cwd = Path.cwd() if cwd is None else cwd
    if second is not None:
        return find_game(cwd if first == "." else first), [second]
    names = {g.name for g in list_games()}
    if normalize_name(first) in names:
        return find_game(first), None
    if (cwd / "game.yaml").is_file():  # inside a game's folder, a state is that game's (Level1 is hundreds')
        return find_game(cwd), [first]
    owners = games_with_state(first)
    if len(owners) == 1:
        return find_game(owners[0]), [first]
    if len(owners) > 1:
        raise UnknownNameError(
            f"Expected one game with a state or recipe named {first!r}; found {len(owners)}: {', '.join(owners)}. "
            f"Name the game: retrokit integrate {owners[0]} {first}"
        )
    raise GameNotFoundError(
        f"Expected a game name, or a state or recipe that one known game has; found {first!r}, which no game "
        f"has, and no game.yaml in {cwd} to make it for. Name the game: retrokit integrate GAME {first}"
        + did_you_mean(first, names)
    )
