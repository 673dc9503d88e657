"""``ramsearch find`` and ``ramsearch suggest``: the subcommands that play a script and look at what it did.

``find`` plays a script that changes a field and one that keeps it, filtering
after each, until one value is left (:mod:`retrokit.ramsearch.find`);
``suggest`` plays a script or a movie and ranks the bytes that change at the
frames the user marks, for a done condition (:mod:`retrokit.ramsearch.events`).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable

from retrokit.commands._ramsearch_common import (
    number,
    open_search,
    print_groups,
    print_table,
    save_field_from,
    session_path,
)
from retrokit.errors import InvalidArgumentError


def register_loops(sub: Callable[[str, str, Callable], argparse.ArgumentParser]) -> None:
    """Add ``find`` and ``suggest`` with ``sub`` (``ramsearch``'s maker of a subcommand with ``--session``)."""
    from retrokit.data.script import SYNTAX

    p = sub(
        "find",
        "find a field in one command: play a script that changes it and one that keeps it, in turn, filtering "
        "after each, until one value is left; show it, and with --save write it into the game's game.yaml",
        _find,
    )
    p.add_argument("name", metavar="NAME", help="the field's name, e.g. lives")
    p.add_argument("--changes", required=True, metavar="SCRIPT", help=f"play that changes the field: {SYNTAX}")
    p.add_argument("--keeps", required=True, metavar="SCRIPT", help="play that leaves it as it is, e.g. '_*60'")
    p.add_argument(
        "--kind", nargs="+", default=["changes"], metavar="KIND",
        help="how --changes changes it: increases, decreases, changes (the default) or becomes N",
    )
    p.add_argument("--rounds", default="10", metavar="N", help="play both scripts at most N times (1 to 10; default 10)")
    p.add_argument("--save", action="store_true", help="write the field found into the game's game.yaml")
    p.add_argument(
        "--range", nargs=2, metavar=("LO", "HI"), help="with --save: the values the field may hold, as range: [LO, HI]"
    )
    p.add_argument("--game-file", metavar="PATH", help="with --save: the game.yaml to write (default: the game's own)")
    p.add_argument("--force", action="store_true", help="with --save: replace a field of the same name")

    p = sub(
        "suggest",
        "suggest bytes for a done condition: play a script (or a movie) and rank the bytes that change at the "
        "frames you mark, such as a death's or a level's end (the session is left as it was)",
        _suggest,
    )
    p.add_argument("--at", required=True, action="append", metavar="FRAME",
                   help="a frame of the play where the event happens, counted from 1; again for each time it does")
    p.add_argument("--script", metavar="SCRIPT", help=f"play this from the game now: {SYNTAX}")
    p.add_argument("--movie", metavar="FILE.bk2", help="play this movie from its start instead")
    p.add_argument("--window", default="2", metavar="N",
                   help="a change up to N frames before or after a mark counts as at it (default 2)")
    p.add_argument("--limit", default="10", metavar="N", help="list at most N bytes (default 10)")


def _find(args: argparse.Namespace) -> int:
    from retrokit.errors import RamSearchError
    from retrokit.ramsearch.find import find_field

    kind, *rest = args.kind
    if len(rest) > 1:
        raise InvalidArgumentError(f"Expected --kind KIND, or --kind becomes N; got --kind {' '.join(args.kind)}.")
    value = number(rest[0], "the number after becomes") if rest else None
    if not args.save and (args.range is not None or args.game_file is not None or args.force):
        raise InvalidArgumentError("Expected --range, --game-file and --force with --save; got them without it.")
    rounds = number(args.rounds, "--rounds")
    with open_search(args) as search:
        played = len(search.labels)
        try:
            finding = find_field(
                search, args.changes, args.keeps, kind, value, rounds=rounds, progress=lambda line: print(line, flush=True)
            )
        finally:
            if len(search.labels) > played:
                search.save(session_path(args))  # what was played and filtered stays in the session, found or not
        if finding.groups:  # the find's own group, or the first groups left
            print_groups(search, finding.groups[:1] if finding.found else finding.groups)
        found = finding.candidate
        if found is None:
            raise RamSearchError(
                f"Expected one value left to call {args.name}; after {finding.rounds} round(s), {finding.reason} "
                f"({finding.count:,} candidates). `retrokit ramsearch show` lists them, `history` the filters."
            )
        print(f"Found {args.name}: {search.layout.format(found.address)} {found.type} ({finding.reason}).")
        if args.save:
            save_field_from(args, search, found.address, found.type)
        else:
            print(f"Save it with: retrokit ramsearch save {args.name} {search.layout.format(found.address)} "
                  f"'{found.type}' --range LO HI   (or find again with --save)")  # fmt: skip
    return 0


def _suggest(args: argparse.Namespace) -> int:
    import numpy as np

    from retrokit.ramsearch.events import suggest_done

    marks = [number(mark, "--at") for mark in args.at]
    window, limit = number(args.window, "--window"), number(args.limit, "--limit")
    if limit is None or limit < 1:
        raise InvalidArgumentError(f"Expected --limit of 1 or more; got {args.limit!r}.")
    with open_search(args) as search:  # played here, never saved: the session stays as it was
        ram = search.ram_frames(args.script, args.movie)
        found, played = suggest_done(
            ram, marks, window=window, limit=limit,
            address_of=lambda position: int(search.layout.addresses(np.array([position]))[0]),
        )  # fmt: skip
        print(f"{len(found)} byte(s) changing at frame(s) {', '.join(map(str, sorted(marks)))} (within {window}) "
              f"of {played:,} played, best first:")  # fmt: skip
        if not found:
            return 0
        rows = [["address", "at marks", "elsewhere", "at each mark", "done, as a field NAME"]]
        for s in found:
            moments = ", ".join(f"{old}->{new} @{frame}" for frame, old, new in s.moments)
            rows.append([search.layout.format(s.address), f"{s.hits}/{len(marks)}", str(s.others), moments, s.condition])
        print_table(rows)
        best = search.layout.format(found[0].address)
        print(f"Save one as a field to use it: retrokit ramsearch save NAME {best} '|u1'")
    return 0
