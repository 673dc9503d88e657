"""Helpers shared by the commands (not a command: the name starts with ``_``)."""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import TYPE_CHECKING

from retrokit import paths

if TYPE_CHECKING:  # every command's register() imports this module: --help must not read the games
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


def add_force_option(parser, help: str, *, said_overwrite: bool = True) -> None:  # an argparse parser
    """Add ``--force``, the one word of every command for "replace what is there" (into ``args.force``).

    ``--overwrite``, the word the older commands (``said_overwrite``) used before, still works on them as a hidden
    alias, so scripts keep running; a command born after the change has no old scripts to keep, so no alias.
    """
    parser.add_argument("--force", action="store_true", help=help)
    if said_overwrite:
        parser.add_argument("--overwrite", dest="force", action="store_true", help=argparse.SUPPRESS)


def add_evaluation_options(parser, workers_help: str) -> None:  # an argparse parser
    """Add the options of a benchmark run that ``evaluate`` and ``demo`` share."""
    parser.add_argument("--levels", default="test", help="test, train, all, or LEVEL,... (default: test)")
    parser.add_argument("--timesteps", type=int, default=None, help="timesteps per level (default: the benchmark's)")
    parser.add_argument("--seed", type=int, default=0, help="the run's seed (default: 0)")
    parser.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1), help=workers_help)


def add_learning_options(parser) -> None:  # an argparse parser
    """Add what a learning agent takes in ``evaluate`` and ``train``: ``--agent-config`` and ``--init``."""
    parser.add_argument("--agent-config", default=None, metavar="NAME|FILE",
                        help="a learning agent's config: paper (the default), quick, or a YAML file (a changed copy)")
    parser.add_argument("--init", default=None, metavar="PATH",
                        help="start from a trained policy: a `retrokit train` folder or its policy.json")


def add_backend_options(parser, local: str, extra: str = "the extra retrokit-rl[ray]") -> None:  # an argparse parser
    """Add ``--backend local|ray`` and ``--ray-address``, which ``evaluate`` and ``train`` share."""
    parser.add_argument("--backend", choices=("local", "ray"), default="local",
                        help=f"{local}, or Ray (default: local; Ray is {extra})")
    parser.add_argument("--ray-address", default=None,
                        help="an existing Ray cluster: HOST:PORT, ray://HOST:PORT or auto (default: start a local Ray)")
