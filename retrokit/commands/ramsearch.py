"""``retrokit ramsearch``: find a game's variables in RAM, one command a process, and save them to its game.yaml.

A search lives in a session file (``ramsearch.session`` in the current
folder unless ``--session`` names another): each subcommand reads it, does one
thing and writes it back. See ``docs/ramsearch.md``::

    retrokit ramsearch new GAME [--state STATE] [--session FILE]
    retrokit ramsearch run [--press BUTTON ...] [--frames N] [--script "START*1 _*60 RIGHT*30"]
                           [--movie FILE.bk2 [--until FRAME]] [--no-snapshot] [--session FILE]
    retrokit ramsearch filter OP [VALUE] [--than previous|first|N|0xADDRESS|changes] [--session FILE]
    retrokit ramsearch show [--limit N] [--json] [--session FILE]
    retrokit ramsearch history | undo | redo [--session FILE]
    retrokit ramsearch poke ADDRESS VALUE [--type TYPE] [--session FILE]
    retrokit ramsearch screenshot FILE.png [--session FILE]
    retrokit ramsearch save NAME ADDRESS TYPE [--range LO HI] [--game-file PATH] [--session FILE]
    retrokit ramsearch find NAME --changes SCRIPT --keeps SCRIPT [--kind increases|decreases|changes|becomes N]
                            [--save [--range LO HI] [--game-file PATH] [--force]] [--rounds N] [--session FILE]
    retrokit ramsearch suggest --at FRAME [--at FRAME ...] (--script SCRIPT | --movie FILE.bk2) [--window N] [--limit N]
    retrokit ramsearch savestate NAME [--default] [--force] [--session FILE]
    retrokit ramsearch movie FILE.bk2 [--force] [--session FILE]
    retrokit ramsearch shell [--session FILE]       # the others typed at a prompt, one a line

The search itself (the session-replacement policy, the listing of groups)
lives in :mod:`retrokit.ramsearch`; this module parses and prints.
"""

from __future__ import annotations

import argparse
import json

from retrokit.commands._common import add_force_option
from retrokit.commands._ramsearch_common import (
    SESSION_HELP,
    VALUES_SHOWN,
    number,
    open_search,
    print_groups,
    save_field_from,
    session_path,
)
from retrokit.commands._ramsearch_loops import register_loops
from retrokit.errors import InvalidArgumentError


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``ramsearch`` command and its subcommands."""
    from retrokit.data.script import SYNTAX
    from retrokit.ramsearch.filters import OPS, THAN_FORMS

    parser = subparsers.add_parser(
        "ramsearch",
        help="find a game's variables in RAM (snapshots, filters, undo) and save them into its game.yaml",
        description="A RAM search in the spirit of BizHawk's RAM Search and Gym Retro's integration tool. Start "
        "with 'new', move the game with 'run', narrow the candidates with 'filter', look with 'show', and write "
        "a find into the game's game.yaml with 'save'; or let 'find' play and filter until one value is left, and "
        "'suggest' rank the bytes that change at an event. The search is kept in a session file between commands.",
    )
    commands = parser.add_subparsers(title="subcommands", metavar="SUBCOMMAND")

    def sub(name: str, help_text: str, run) -> argparse.ArgumentParser:
        p = commands.add_parser(name, help=help_text, description=help_text[0].upper() + help_text[1:] + ".")
        p.add_argument("--session", metavar="FILE", default=None, help=SESSION_HELP)
        p.set_defaults(run=run)
        return p

    p = sub("new", "start a search from a save state: the first snapshot, every type at every address", _new)
    p.add_argument("game", metavar="GAME", help="the game, e.g. Dasher-Genesis")
    p.add_argument("--state", help="the save state to start from (default: the game's default state)")
    p.add_argument(
        "--types", metavar="CODES",
        help="comma-separated type codes to search, or bits (default: every type Gym Retro infers, and the "
        "3-byte ones: <u3 >u3 <i3 >i3 <d3 >d3)",
    )
    p.add_argument("--force", action="store_true", help="replace an existing session file")

    p = sub("run", "move the game on (hold buttons, play a script or a movie), then take a snapshot", _run)
    p.add_argument(
        "--press",
        nargs="+",
        action="extend",
        default=[],
        metavar="BUTTON",
        help="buttons to hold together, by the game's names (RIGHT, B; 2:START for port 2); "
        "--press B --press UP holds both",
    )
    p.add_argument("--frames", metavar="N", help="frames to run (default: 1)")
    p.add_argument("--script", metavar="STEPS", help=f"play a sequence of inputs instead: {SYNTAX}")
    p.add_argument("--movie", metavar="FILE.bk2", help="play this movie from its start instead")
    p.add_argument("--until", metavar="FRAME", help="stop the movie after this many frames (default: its end)")
    p.add_argument("--state", help="load this save state first")
    p.add_argument("--no-snapshot", action="store_true", help="move the game on without taking a snapshot")

    p = sub("filter", "keep the candidates whose newest value passes a comparison", _filter)
    p.add_argument("op", metavar="OP", help=", ".join(OPS))
    p.add_argument(
        "value", nargs="?", metavar="VALUE", help="the number to compare with (for changed-by: the difference)"
    )
    p.add_argument("--than", metavar="REF", help=f"what to compare with: {THAN_FORMS}")

    p = sub("show", "list the candidates: address, type, scale, change count, value at each snapshot", _show)
    p.add_argument("--limit", default="20", metavar="N", help="list at most N (default: 20; 0: all)")
    p.add_argument("--json", action="store_true", help='print a JSON list of {"address", "type", "values"}')

    sub("history", "list the snapshots, numbered from 0 in the order taken (for --than N), and the filters", _history)
    sub("undo", "undo the last filter", _undo)
    sub("redo", "apply the last undone filter again", _redo)
    sub("shell", "read subcommands from a prompt (or standard input), one a line, until 'quit'", _shell)

    p = sub("poke", "write a value into RAM, to test a guess", _poke)
    p.add_argument("address", metavar="ADDRESS", help="the console address, e.g. 0xFF002B")
    p.add_argument("value", metavar="VALUE", help="the value")
    p.add_argument("--type", default="|u1", help="its type code (default: |u1)")

    p = sub("screenshot", "save the screen (the next frame, so pokes show) as a PNG", _screenshot)
    p.add_argument("file", metavar="FILE.png")
    add_force_option(p, "replace an existing file")

    p = sub("save", "write a field into the game's game.yaml, keeping its comments and layout", _save)
    p.add_argument("name", metavar="NAME", help="the field's name, e.g. lives")
    p.add_argument("address", metavar="ADDRESS", help="its console address, e.g. 0xFF002B")
    p.add_argument("type", metavar="TYPE", help="its type code, e.g. '|u1'")
    p.add_argument(
        "--game-file", metavar="PATH",
        help="the game.yaml to write (default: the game's own; a shipped game's copy in the data folder, made first)",
    )
    p.add_argument("--force", action="store_true", help="replace a field of the same name")
    p.add_argument(
        "--range", nargs=2, metavar=("LO", "HI"), help="the values the field may hold, written as range: [LO, HI]"
    )

    register_loops(sub)

    p = sub("savestate", "save the game's state now as a state of the game, in the data folder", _savestate)
    p.add_argument("name", metavar="NAME", help="the state's name, e.g. Level1")
    p.add_argument("--default", action="store_true", help="make it the state make(game) starts from")
    p.add_argument("--force", action="store_true", help="replace a different state of that name")

    p = sub("movie", "write the inputs played since the start state as a stable-retro movie", _movie)
    p.add_argument("file", metavar="FILE.bk2")
    p.add_argument("--force", action="store_true", help="replace an existing file")
    parser.set_defaults(run=run)


SUBCOMMANDS = (
    "new", "run", "filter", "show", "history", "undo", "redo", "poke", "screenshot", "save", "find", "suggest",
    "savestate", "movie", "shell",
)  # fmt: skip


def run(args: argparse.Namespace) -> int:
    """``retrokit ramsearch`` without a subcommand: say which there are."""
    raise InvalidArgumentError(
        f"Expected a subcommand of ramsearch: {', '.join(SUBCOMMANDS)}; got none. See: retrokit ramsearch --help"
    )


# --- subcommands ----------------------------------------------------------------------------------


def _new(args: argparse.Namespace) -> int:
    from retrokit.data.games import find_game
    from retrokit.ramsearch import RamSearch
    from retrokit.ramsearch.session import check_new_session

    path = session_path(args)
    game = find_game(args.game)
    check_new_session(path, game.name, force=args.force)
    with RamSearch(game, args.state, types=args.types) as search:
        search.save(path, overwrite=args.force)
        print(
            f"New search of {game.name} from {search.state or 'power-on'}: {search.count:,} candidates "
            f"({len(search.types)} types at every address of {search.layout.describe()}). Session: {path}"
        )
    return 0


def _run(args: argparse.Namespace) -> int:
    frames, until = number(args.frames, "--frames"), number(args.until, "--until")
    if args.movie is None and until is not None:
        raise InvalidArgumentError("Expected --until with --movie FILE.bk2; got --until alone.")
    if args.movie is not None and (args.press or frames is not None or args.state or args.script is not None):
        raise InvalidArgumentError(
            "Expected either --movie (with --until) or --press/--frames/--script/--state, not both."
        )
    if args.script is not None and (args.press or frames is not None):
        raise InvalidArgumentError(
            "Expected either --script or --press/--frames, not both: a script holds its own buttons, e.g. RIGHT*30."
        )
    snapshot = not args.no_snapshot
    with open_search(args) as search:
        if args.movie is not None:
            index = search.play(args.movie, until, snapshot=snapshot)
        elif args.script is not None:
            index = search.run_script(args.script, state=args.state, snapshot=snapshot)
        else:
            index = search.run(args.press, 1 if frames is None else frames, state=args.state, snapshot=snapshot)
        search.save(session_path(args))
        if index is None:
            frames_played = sum(count for count, _ in search.inputs)
            print(f"Moved on, no snapshot taken ({frames_played} frames played since the start state).")
        else:
            print(f"Snapshot {index}: {search.labels[index]}.")
    return 0


def _filter(args: argparse.Namespace) -> int:
    than = args.than
    if than is not None and than.lower().startswith("0x"):  # an address; a decimal number is a snapshot
        try:
            than = int(than, 16)
        except ValueError:
            pass  # the engine names what --than takes, and the closest one
    with open_search(args) as search:
        before = search.count
        after = search.filter(args.op, number(args.value, "VALUE"), than)
        search.save(session_path(args))
        print(f"{search.history[-1]}: {before:,} -> {after:,} candidates.")
    return 0


def _show(args: argparse.Namespace) -> int:
    from retrokit.ramsearch.candidates import check_listable, list_groups

    limit = number(args.limit, "--limit")
    if limit is None or limit < 0:
        raise InvalidArgumentError(f"Expected --limit of 0 (all) or more, got {args.limit!r}.")
    with open_search(args) as search:
        if args.json:
            check_listable(search.count, limit)
            candidates = search.candidates(limit or None)
            print(json.dumps([{"address": c.address, "type": c.type, "values": list(c.values)} for c in candidates]))
            return 0
        listing = list_groups(search.count, search.candidates, limit, len(search.types))
        total, shown = listing.total, listing.groups
        print(
            f"{total:,} candidate{'s' * (total != 1)}"
            + (
                f" in {listing.count:,} group{'s' * (listing.count != 1)} (types reading the same bytes alike)"
                if listing.count is not None
                else ""
            )
            + (f"; the first {len(shown)} by address:" if listing.more else ":")
        )
        if not shown:
            return 0
        print_groups(search, shown)
        first = max(0, len(search.labels) - VALUES_SHOWN)
        print("snapshots: " + "; ".join(f"{i} {label}" for i, label in enumerate(search.labels) if i >= first))
    return 0


def _history(args: argparse.Namespace) -> int:
    with open_search(args) as search:
        print(f"{len(search.labels)} snapshot{'s' * (len(search.labels) != 1)} (--than N compares with snapshot N):")
        for index, label in enumerate(search.labels):
            print(f"  {index}  {label}")
        filters = search.history
        print(f"{len(filters)} filter{'s' * (len(filters) != 1)}{':' if filters else '.'}")
        for label in filters:
            print(f"  {label}")
        print(f"{search.count:,} candidate{'s' * (search.count != 1)} left.")
    return 0


def _undo(args: argparse.Namespace) -> int:
    return _step_history(args, redo=False)


def _redo(args: argparse.Namespace) -> int:
    return _step_history(args, redo=True)


def _step_history(args: argparse.Namespace, *, redo: bool) -> int:
    with open_search(args) as search:
        before = search.count
        label = search.redo() if redo else search.undo()
        search.save(session_path(args))
        print(f"{'Redid' if redo else 'Undid'} {label}: {before:,} -> {search.count:,} candidates.")
    return 0


def _poke(args: argparse.Namespace) -> int:
    address, value = number(args.address, "ADDRESS"), number(args.value, "VALUE")
    with open_search(args) as search:
        search.poke(address, value, args.type)
        search.save(session_path(args))
        print(f"Wrote {value} as {args.type} at {search.layout.format(address)}; the next run starts from it.")
    return 0


def _screenshot(args: argparse.Namespace) -> int:
    with open_search(args) as search:
        path = search.screenshot(args.file, overwrite=args.force)
        height, width = search.emulator.screen_shape()
        print(f"Saved the screen ({width}x{height}) to {path}.")
    return 0


def _shell(args: argparse.Namespace) -> int:
    """Run subcommands typed one a line (``filter equal 3``), each as its own command, on one session."""
    import shlex
    import sys

    from retrokit.errors import RetrokitError

    # Its own parser of these subcommands: a command never imports the CLI above it.
    parser = argparse.ArgumentParser(prog="retrokit")
    register(parser.add_subparsers())
    interactive = sys.stdin.isatty()
    session = ["--session", args.session] if args.session else []
    while True:
        try:
            line = input("ramsearch> " if interactive else "")
        except EOFError:
            return 0
        try:
            words = shlex.split(line)
        except ValueError as exc:
            print(f"retrokit: error: Expected a line of words, as a shell splits them; found {exc}.", file=sys.stderr)
            continue
        if not words or words[0].startswith("#"):
            continue
        if words[0] in ("quit", "exit"):
            return 0
        if words[0] == "shell":
            print("retrokit: error: Expected a subcommand other than shell inside the shell.", file=sys.stderr)
            continue
        try:
            parsed = parser.parse_args(["ramsearch", *words, *session])
            parsed.run(parsed)
        except SystemExit:  # argparse printed its usage error or help
            continue
        except RetrokitError as exc:
            print(f"retrokit: error: {exc}", file=sys.stderr)


def _save(args: argparse.Namespace) -> int:
    with open_search(args) as search:
        save_field_from(args, search, number(args.address, "ADDRESS"), args.type)
    return 0


def _savestate(args: argparse.Namespace) -> int:
    with open_search(args) as search:
        outcome = search.save_state(args.name, default=args.default, force=args.force)
        done = {"made": "Saved", "replaced": "Replaced", "up to date": "Kept (already the same state)"}[outcome.status]
        print(f"{done} state {args.name} of {search.game.name}: {outcome.path}.")
        if args.default:
            print(f"Default state of {search.game.name} is now {args.name} ({outcome.path.parent / 'game.yaml'}).")
    return 0


def _movie(args: argparse.Namespace) -> int:
    with open_search(args) as search:
        path = search.write_movie(args.file, overwrite=args.force)
        frames = sum(count for count, _ in search.inputs)
        print(f"Wrote {frames} frames played since the start state to {path}.")
    return 0


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit ramsearch new Dasher-Genesis --state Zone1.Act1",
    "retrokit ramsearch run --press RIGHT B --frames 60",
    "retrokit ramsearch run --movie Mine-000000.bk2 --until 300",
    "retrokit ramsearch run --script 'START*1 _*60 RIGHT*30 RIGHT+B*2'   # taps, holds and waits",
    "retrokit ramsearch run --script 'LEFT*40' --no-snapshot",
    "retrokit ramsearch filter increased                 # than the previous snapshot",
    "retrokit ramsearch filter equal 3                   # equal to the number 3",
    "retrokit ramsearch filter unchanged --than first",
    "retrokit ramsearch filter increased --than 2        # than snapshot 2 (ramsearch history)",
    "retrokit ramsearch filter greater --than 0xFF0020   # than the value at that address",
    "retrokit ramsearch filter changed-by 1",
    "retrokit ramsearch filter greater 2 --than changes  # changed more than twice",
    "retrokit ramsearch show --limit 50",
    "retrokit ramsearch history",
    "retrokit ramsearch undo",
    "retrokit ramsearch redo",
    "retrokit ramsearch poke 0xFF002B 5 --type '|u1'",
    "retrokit ramsearch screenshot poked.png",
    "retrokit ramsearch save lives 0xFF002B '|u1'",
    "retrokit ramsearch save lives 0xFF002B '|u1' --range 0 9",
    "retrokit ramsearch find lives --changes 'RIGHT*200' --keeps '_*130' --kind decreases --save --range 0 9",
    "retrokit ramsearch find score --changes '(RIGHT*10 A*2)*5' --keeps '_*30' --kind increases",
    "retrokit ramsearch suggest --script 'RIGHT*400' --at 133 --at 331   # bytes changing as the player dies",
    "retrokit ramsearch suggest --movie level1.bk2 --at 1520 --window 0",
    "retrokit ramsearch savestate Level1 --default",
    "retrokit ramsearch movie level1.bk2",
    "retrokit ramsearch shell --session dasher.session",
]
