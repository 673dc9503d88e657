"""What the ``ramsearch`` subcommands share: numbers, the session, the candidate table, saving a field."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from retrokit.errors import InvalidArgumentError

if TYPE_CHECKING:
    from retrokit.ramsearch import Candidate, RamSearch

SESSION_HELP = "the session file (default: ramsearch.session in the current folder)"
VALUES_SHOWN = 8  # snapshots whose values `show` prints; older ones are elided


def number(text: str | None, what: str) -> int | None:
    """A whole number the user typed (decimal, or hex as 0xFF002B), or ``None`` for none.

    Raises:
        InvalidArgumentError: It is not one.
    """
    if text is None:
        return None
    try:
        return int(text, 0)
    except ValueError:
        raise InvalidArgumentError(
            f"Expected {what} as a whole number (decimal, or hex as 0xFF002B), got {text!r}."
        ) from None


def session_path(args: argparse.Namespace) -> str:
    """The session file: ``--session``, or the default one in the current folder."""
    from retrokit.ramsearch import DEFAULT_SESSION

    return args.session or DEFAULT_SESSION


def open_search(args: argparse.Namespace) -> RamSearch:
    """The search the session file holds."""
    from retrokit.ramsearch import RamSearch

    return RamSearch.load(session_path(args))


def group_rows(search: RamSearch, groups: list[list[Candidate]]) -> list[list[str]]:
    """One row per group of candidates that read the same bytes the same way (the narrowest type first)."""
    first = max(0, len(search.labels) - VALUES_SHOWN)
    rows = []
    for group in groups:
        head = group[0]
        shown = ("... " if first else "") + " ".join(str(v) for v in head.values[first:])
        others = [
            c.type if c.address == head.address else f"{c.type}@{search.layout.format(c.address)}" for c in group[1:]
        ]
        also = f"  (also {' '.join(others)})" if others else ""
        rows.append([search.layout.format(head.address), head.type, head.scale or "-", str(head.changes), shown + also])
    return rows


def print_groups(search: RamSearch, groups: list[list[Candidate]]) -> None:
    """The table ``show`` prints: a header, then a row per group, its values at the newest snapshots."""
    first = max(0, len(search.labels) - VALUES_SHOWN)
    header = ["address", "type", "scale", "changes", f"values at snapshots {first}-{len(search.labels) - 1}"]
    print_table([header, *group_rows(search, groups)])


def print_table(rows: list[list[str]]) -> None:
    """Rows of five columns: the first four padded to their widest cell, the last as it is (it may be long)."""
    widths = [max(len(r[i]) for r in rows) for i in range(4)]
    for row in rows:
        print("  ".join(cell.ljust(width) for cell, width in zip(row[:4], widths)) + "  " + row[4])


def save_field_from(args: argparse.Namespace, search: RamSearch, address: int, type_code: str) -> None:
    """Write ``args.name`` at ``address`` as ``type_code`` (with ``--range``, ``--game-file``, ``--force``) and say so."""
    value_range = None if args.range is None else tuple(number(v, "--range") for v in args.range)
    path = search.save_field(
        args.name, address, type_code, game_file=args.game_file, force=args.force, value_range=value_range
    )
    extra = "" if value_range is None else f", range [{value_range[0]}, {value_range[1]}]"
    print(f"Wrote field {args.name} ({search.layout.format(address)}, {type_code}{extra}) into {path}.")
