"""The save states retrokit and the stable-retro wheel ship, known by the SHA-256 of their files.

A shipped state needs no crash probe, but "shipped" is decided by content,
not by where a file lies: the stable-retro wheel's ``RECORD`` lists the
SHA-256 of each of its files, and retrokit's own ``games/`` carries
:data:`STATE_HASHES`, a list of the SHA-256 of each ``.state`` file in it
(written by ``python -m retrokit.data.shipped``, checked current by
``tests/test_trust.py``). A file whose bytes are on neither list is not
shipped, wherever it is.
"""

from __future__ import annotations

import base64
import functools
import hashlib
import importlib.metadata
import sys
from pathlib import Path

from retrokit import paths

STATE_HASHES = "STATES.sha256"
"""The file in ``games/`` listing ``<sha256>  <Game>/<Name>.state``, one shipped state a line."""


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
    try:
        files = importlib.metadata.distribution("stable-retro").files or []
    except importlib.metadata.PackageNotFoundError:
        files = []
    for file in files:
        if file.hash is not None and file.hash.mode == "sha256" and str(file).endswith(".state"):
            value = file.hash.value
            digests.add(base64.urlsafe_b64decode(value + "=" * (-len(value) % 4)).hex())
    return frozenset(digests)


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


if __name__ == "__main__":  # python -m retrokit.data.shipped: rewrite games/STATES.sha256 after adding a state
    root = Path(__file__).resolve().parents[2] / "games"
    paths.atomic_write(root / STATE_HASHES, state_hashes(root).encode(), overwrite=True)
    sys.exit(0)
