"""The save states retrokit and the stable-retro wheel ship, known by the SHA-256 of their files.

A shipped state needs no crash probe, but "shipped" is decided by content,
not by where a file lies: the stable-retro wheel's ``RECORD`` lists the
SHA-256 of each of its files, and retrokit's own ``games/`` carries
:data:`STATE_HASHES`, a list of the SHA-256 of each ``.state`` file in it
(written by ``python -m retrokit.data.shipped``, checked current by
``tests/test_trust.py``). A file whose bytes are on neither list is not
shipped, wherever it is.

Which game a shipped state is for is known too (:mod:`retrokit.data.statecheck`
refuses it for another game): a file of the wheel by the folder ``RECORD``
lists it in, and the state inside, however it is wrapped again (its record
stripped, a movie's ``Core.bin``), by :data:`WHEEL_STATE_HASHES`, which
lists the digest of the state in each of the wheel's ``.state`` files, every
game's (Pong's ``Start.state`` inflated and compressed again is still known as
Pong's). Only its lines whose file the installed wheel holds, by its
``RECORD`` digest, are used.
"""

from __future__ import annotations

import functools
import hashlib
import sys
from pathlib import Path

from retrokit import paths
from retrokit.wheel import wheel_files

STATE_HASHES = "STATES.sha256"
"""The file in ``games/`` listing ``<sha256>  <Game>/<Name>.state``, one shipped state a line."""
WHEEL_STATE_HASHES = "WHEEL-STATES.sha256"
"""The file in ``games/`` listing ``<state sha256>  <file sha256>  <kind>/<Folder>/<Name>.state`` for the wheel."""


@functools.cache
def shipped_digests() -> frozenset[str]:
    """The SHA-256 (hex) of every ``.state`` file that retrokit's ``games/`` or the stable-retro wheel ships."""
    digests: set[str] = set()
    games = paths.repo_games_dir()
    if games is not None:
        try:
            text = (games / STATE_HASHES).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            text = ""
        digests.update(line.split()[0] for line in text.splitlines() if line.strip())
    digests.update(wheel_state_files())
    return frozenset(digests)


@functools.cache
def wheel_state_files() -> dict[str, tuple[str, ...]]:
    """The SHA-256 (hex) of every ``.state`` file the stable-retro wheel ships, to its paths in the wheel's ``data``
    folder (``stable/Airstriker-Genesis-v0/Level1.state``; a few files are there twice), from the wheel's ``RECORD``."""
    found: dict[str, tuple[str, ...]] = {}
    for path, _, digest in wheel_files(lambda path: path.endswith(".state") and "/data/" in f"/{path}"):
        parts = path.split("/")
        found[digest] = (*found.get(digest, ()), "/".join(parts[parts.index("data") + 1 :]))
    return found


def wheel_state_hashes() -> str:
    """The text of :data:`WHEEL_STATE_HASHES` for the installed wheel: the digest of the state inside each of its
    ``.state`` files, every game's (about 1,800 files, 1.2 GB once inflated: seconds, so it is done once, here, when
    retrokit is packaged, and never when a state is loaded)."""
    from retrokit.data.states import read_state_file
    from retrokit.errors import RetrokitError

    lines = []
    for folder in (folder for kind in paths.wheel_data_dirs() for folder in sorted(kind.iterdir()) if folder.is_dir()):
        for path in sorted(folder.glob("*.state")):
            try:
                data = read_state_file(path).data
            except RetrokitError:  # a file no core can load identifies nothing
                continue
            blob = path.read_bytes()
            where = path.relative_to(folder.parent.parent).as_posix()
            lines.append(f"{hashlib.sha256(data).hexdigest()}  {hashlib.sha256(blob).hexdigest()}  {where}")
    return "\n".join(lines) + "\n"


def is_shipped_blob(blob: bytes) -> bool:
    """Whether ``blob``, a ``.state`` file's bytes, is exactly a state file retrokit or the wheel ships."""
    return hashlib.sha256(blob).hexdigest() in shipped_digests()


def state_hashes(games: Path) -> str:
    """The text of :data:`STATE_HASHES` for the ``.state`` files under ``games``."""
    lines = [
        f"{hashlib.sha256(path.read_bytes()).hexdigest()}  {path.relative_to(games).as_posix()}"
        for path in sorted(games.glob("*/*.state"))
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":  # python -m retrokit.data.shipped: rewrite games/*STATES.sha256 after adding a state
    root = Path(__file__).resolve().parents[2] / "games"
    paths.atomic_write(root / STATE_HASHES, state_hashes(root).encode(), overwrite=True)
    paths.atomic_write(root / WHEEL_STATE_HASHES, wheel_state_hashes().encode(), overwrite=True)
    sys.exit(0)
