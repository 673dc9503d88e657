"""Helpers shared by the commands (not a command: the name starts with ``_``)."""

from __future__ import annotations

import os
from pathlib import Path

from retrokit import paths
from retrokit.data.games import Game


def rom_status(game: Game, data_dir: str | os.PathLike[str] | None = None) -> tuple[str, Path | None]:
    """Return ``("bundled" | "imported" | "missing", path)`` for a game's ROM."""
    path = game.rom_path(data_dir)
    if path is None:
        return "missing", None
    return ("imported" if path.is_relative_to(paths.roms_dir(data_dir)) else "bundled"), path


def add_data_dir_option(parser) -> None:  # an argparse parser
    """Add ``--data-dir``, the per-user data folder override."""
    parser.add_argument(
        "--data-dir",
        metavar="DIR",
        help=f"the data folder that holds imported ROMs (default: ${paths.DATA_ENV}, "
        "else $XDG_DATA_HOME/retrokit, else ~/.local/share/retrokit)",
    )
