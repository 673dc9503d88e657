"""``retrokit import PATH... [--game NAME]``: copy the ROMs of known games into the data folder."""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import TYPE_CHECKING

from retrokit.commands._common import add_data_dir_option, add_force_option, rom_status
from retrokit.errors import printable

if TYPE_CHECKING:
    from retrokit.data.importer import UnmatchedFile

SHOWN = 10


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``import`` command."""
    parser = subparsers.add_parser(
        "import",
        help="import ROMs of known games from folders and zip files",
        description="Search files, folders and zip files for the ROMs of known games (by SHA-1, "
        "by stable-retro's rules), and copy each match into the data folder. A different ROM "
        "already imported is never replaced unless --force is given. On a terminal, a progress bar counts "
        "the files searched, on standard error (none in a pipe or a log file).",
    )
    parser.add_argument("paths", nargs="*", metavar="PATH", help="files, folders or zip files to search")
    parser.add_argument("--from", dest="package", metavar="PACKAGE",
                        help="also search the ROMs an installed Python package ships (ale-py: Atari 2600 ROMs)")
    parser.add_argument("--game", metavar="NAME", help="show the SHA-1s this game expects, and whether its ROM is present")
    add_force_option(parser, "replace a different ROM already imported")
    parser.add_argument("-v", "--verbose", action="store_true", help="list every file that matched nothing")
    add_data_dir_option(parser)
    parser.set_defaults(run=run)


def _section(title: str, lines: list[str], verbose: bool) -> None:
    if not lines:
        return
    print(f"{title} ({len(lines)}):")
    shown = lines if verbose else lines[:SHOWN]
    for line in shown:
        print(f"  {printable(line)}")  # file names: a control character in one must not reach the terminal
    if len(shown) < len(lines):
        print(f"  ... and {len(lines) - len(shown)} more (-v lists them all)")


def _unmatched(entry: UnmatchedFile) -> str:
    return f"{entry.source}  SHA-1 {entry.sha1}  {entry.system or 'system unknown'}"


def run(args: argparse.Namespace) -> int:
    """Import ROMs, and/or show what a game expects."""
    from retrokit.benchmark.progress import is_terminal
    from retrokit.data.games import find_game
    from retrokit.data.importer import import_roms, package_roms
    from retrokit.errors import FileSystemError, InvalidArgumentError, shell_word

    if args.package:
        args.paths = [*args.paths, str(package_roms(args.package))]
    if not args.paths and not args.game:
        raise InvalidArgumentError(
            "Expected at least one PATH to search (or --game NAME, or --from PACKAGE); found none. "
            "Run, for example: retrokit import ~/roms"
        )
    game = find_game(args.game) if args.game else None
    for path in args.paths:  # checked before any is searched: a typo must not look like "nothing found"
        if not os.path.lexists(path):
            raise FileSystemError(
                f"Expected a file, folder or zip file to search; found no such path: {path!r}. Check the path."
            )
    status = 0
    if args.paths:
        report = import_roms(args.paths, data_dir=args.data_dir, overwrite=args.force, progress=is_terminal())
        print(f"Imported {len(report.imported)} ROM{'s' * (len(report.imported) != 1)} into {report.data_dir / 'roms'}.")
        _section("Imported", [f"{r.game} <- {r.source}" for r in report.imported], True)
        _section("Already imported", [f"{r.game} <- {r.source}" for r in report.already_present], args.verbose)
        _section(
            "Not overwritten, a different file is there (pass --force to replace it)",
            [f"{c.game}: {c.path} and {c.source} differ ({c.differs})" for c in report.conflicts],
            True,
        )
        _section(
            "Refused: a known game's ROM whose header its core cannot run (fix the header, or import a good dump)",
            [f"{game}: {label}: {why}" for label, game, why in report.refused],
            True,
        )
        _section("Matched no known game (SHA-1, likely system)", [_unmatched(u) for u in report.unmatched], args.verbose)
        _section("Skipped", [f"{label}: {why}" for label, why in report.skipped], args.verbose)
        if report.not_roms:
            exts = sorted({Path(label).suffix or "(none)" for label in report.not_roms})
            print(f"Left out {len(report.not_roms)} file{'s' * (len(report.not_roms) != 1)} that are no ROMs "
                  f"(extension {', '.join(exts)}; no header or size of a system's ROMs).")
        _section("Games whose data files cannot be read", [f"{n}: {e}" for n, e in report.broken_games], args.verbose)
        likely = [u for u in report.unmatched if u.system is not None]
        if likely:
            print(f"A game nobody has integrated yet? Start one with: retrokit new {shell_word(likely[0].source)} "
                  f"--name NAME-{likely[0].system} (retrokit docs integrate)")
        status = 1 if report.conflicts or report.refused else 0
    if game is not None:
        where, path = rom_status(game, args.data_dir)
        print(f"{game.name} ({game.system}) accepts a ROM with SHA-1:")
        for sha1 in game.sha1s or ("(none listed in its data file)",):
            print(f"  {sha1}")
        if path is not None:
            print(f"Its ROM is {where}: {path}")
        else:
            print(f"Its ROM is missing: expected at {game.imported_rom_path(args.data_dir)}. "
                  "Import it with: retrokit import /path/to/your/roms")
    return status


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit import ~/roms                              # search a folder (and the .zip files in it)",
    "retrokit import Sonic.zip Airstriker.md -v",
    "retrokit import --game SonicTheHedgehog-Genesis     # which ROM that game expects",
    "retrokit import --from ale-py                       # the Atari 2600 ROMs ale-py ships",
]
