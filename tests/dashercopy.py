"""A smaller copy of Dasher's (or another game's) folder, for tests that validate it but are not about every state and movie.

A validation of Dasher as shipped plays every state's smoke runs and replays
its six solution movies (5,700 frames): about 9 CPU-seconds. A test whose
claim is that a validation runs and reports (the studio's Validate, its
progress, its JSON) passes on a copy with fewer states and movies just as
well; tests/test_validate.py validates every folder of games/ in full.
"""

from __future__ import annotations

import shutil
from collections.abc import Iterable
from pathlib import Path

DASHER = Path(__file__).resolve().parent.parent / "games" / "Dasher-Genesis"


def dasher_copy(parent: Path, states: Iterable[str], movies: Iterable[str] = ()) -> Path:
    """Copy Dasher's folder to ``parent/Dasher-Genesis`` with only these states and solution movies.

    Args:
        parent: Where the copy's folder goes.
        states: The states kept (by name); game.yaml's default and 2-player default must be among them.
        movies: The solution movies kept (by name); game.yaml's ``movies`` entries of the others are left out.

    Returns:
        The copy's folder.
    """
    return game_copy(DASHER, parent, states, movies)


def game_copy(source: Path, parent: Path, states: Iterable[str] | None = None, movies: Iterable[str] = ()) -> Path:
    """Copy a game's folder to ``parent/<its name>`` with only these states (``None``: all) and solution movies.

    Returns:
        The copy's folder.
    """
    kept_states, movies = (None if states is None else set(states)), set(movies)

    def left_out(folder: str, names: list[str]) -> list[str]:
        return [n for n in names if (n.endswith(".state") and kept_states is not None
                                     and n.removesuffix(".state") not in kept_states)
                or (n.endswith(".bk2") and n.removesuffix(".bk2") not in movies)]  # fmt: skip

    folder = parent / source.name
    shutil.copytree(source, folder, ignore=left_out)
    game_yaml = folder / "game.yaml"
    head, found, section = game_yaml.read_text().partition("\nmovies:\n")  # the movies section comes last
    if found:
        kept = [line for line in section.splitlines() if line.split(":", 1)[0].strip() in movies]
        game_yaml.write_text(head + ("\nmovies:\n" + "\n".join(kept) if kept else "") + "\n")
    return folder
