"""Temporary work folders of builds, named for their owner so that a killed build's folder is removed later.

``retrokit build-core`` downloads about 150 MB into a temporary folder and
unpacks the core's source there. :class:`tempfile.TemporaryDirectory` removes
it on any exception, but nothing does when the process is killed (SIGKILL, the
OOM killer, a closed terminal). So the folders are named
``retrokit-build-<pid>-<random>``, and every build first removes the ones of
this user whose owner process is gone.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

PREFIX = "retrokit-build-"
_NAME = re.compile(rf"{re.escape(PREFIX)}(\d{{1,10}})-\w+")


def _alive(pid: int) -> bool:
    """Whether a process ``pid`` exists (one of another user's counts: it may be the owner)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):  # someone else's process, or no PID this system can have
        return True
    return True


def remove_stale(parent: Path | str | None = None) -> list[Path]:
    """Remove the work folders in ``parent`` (default: the temporary folder) whose owner process is gone.

    Only folders of this user named as :func:`work_folder` names them are
    touched, never through a symlink. A folder that cannot be removed is left.

    Returns:
        The folders removed.
    """
    parent = Path(parent or tempfile.gettempdir())
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return []
    removed = []
    for entry in entries:
        match = _NAME.fullmatch(entry.name)
        if match is None:
            continue
        try:
            info = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        pid = int(match.group(1))
        if not entry.is_dir(follow_symlinks=False) or info.st_uid != os.getuid() or _alive(pid):
            continue
        shutil.rmtree(entry.path, ignore_errors=True)
        if not os.path.lexists(entry.path):
            removed.append(Path(entry.path))
    return removed


@contextmanager
def work_folder(parent: Path | str | None = None) -> Iterator[Path]:
    """A new work folder named for this process, removed on exit; stale ones of killed builds go first."""
    remove_stale(parent)
    with tempfile.TemporaryDirectory(prefix=f"{PREFIX}{os.getpid()}-", dir=parent) as folder:
        yield Path(folder)
