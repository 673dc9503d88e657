"""The stable-retro wheel's ``RECORD``: the files it installed, with the SHA-256 of each, read once per process.

retrokit uses the wheel's files (cores, save states, the free ROM), never its Python. Which of them a state or
a core is, and the digest the wheel vouches for, come from ``RECORD``. ``Distribution.files`` makes a path
object of each of its ~6,300 lines (a tenth of a second, twice per process that makes an env); the few lines
wanted are picked from the text first.
"""

from __future__ import annotations

import base64
import csv
import functools
import importlib.metadata
from collections.abc import Callable
from pathlib import Path


@functools.cache
def _record() -> tuple[importlib.metadata.Distribution, list[str]] | None:
    try:
        dist = importlib.metadata.distribution("stable-retro")
    except importlib.metadata.PackageNotFoundError:
        return None
    return dist, (dist.read_text("RECORD") or "").splitlines()


def wheel_version() -> str | None:
    """The installed wheel's version, or ``None`` without one."""
    found = _record()
    return None if found is None else found[0].version


def wheel_files(wanted: Callable[[str], bool]) -> list[tuple[str, Path, str]]:
    """The files ``RECORD`` lists with a SHA-256 whose path (``stable_retro/cores/x_libretro.so``) is ``wanted``:
    each as that path, where it is installed, and its SHA-256 in hex."""
    found = _record()
    if found is None:
        return []
    dist, lines = found
    files = []
    # A line is PATH,HASH,SIZE (csv: PATH is quoted if it holds a comma or a quote); most lines are not wanted.
    for path, hashed, *_ in csv.reader(line for line in lines if wanted(line.rsplit(",", 2)[0].strip('"'))):
        mode, _, value = hashed.partition("=")
        if mode == "sha256" and wanted(path):
            digest = base64.urlsafe_b64decode(value + "=" * (-len(value) % 4)).hex()
            files.append((path, Path(str(dist.locate_file(path))), digest))
    return files
