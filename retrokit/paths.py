"""Where retrokit's files live, and how they are written safely.

Game folders are searched, in order, in:

1. every folder in ``RETROKIT_GAMES`` (separated by :data:`os.pathsep`),
2. the per-user data folder's ``games/`` (what ``retrokit integrate`` and
   ``retrokit play`` make: a game folder there extends or overrides the
   shipped one, and may hold only states and scenarios),
3. the bundled integrations: the checkout's ``games/`` folder (next to the
   ``retrokit`` package), or its copy inside an installed package,
4. the stable-retro wheel's ``data/stable``, ``data/experimental`` and
   ``data/contrib`` folders.

The per-user data folder holds imported ROMs (``<data>/roms/<Game>/rom.<ext>``)
and the user's game folders (``<data>/games/<Game>/``): :mod:`retrokit.datafolder`
(whose names this module re-exports) finds it, and is the one way to a path in it.

The stable-retro wheel is located without importing its Python code.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import functools
import importlib.util
import os
import stat
import tempfile
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

from retrokit.datafolder import (  # noqa: F401 (re-exported: the data folder's names, as callers know them)
    DATA_ENV,
    data_dir,
    data_path,
    imported_rom_path,
    inside_data,
    records_dir,
    roms_dir,
    user_games_dir,
)
from retrokit.errors import FileConflictError, FileSystemError, UnknownNameError, did_you_mean, shown

GAMES_ENV = "RETROKIT_GAMES"
WHEEL_DATA_KINDS = ("stable", "experimental", "contrib")


@functools.lru_cache(maxsize=1)
def wheel_dir() -> Path | None:
    """Return the installed ``stable_retro`` package folder, or ``None``.

    ``importlib.util.find_spec`` on a top-level package locates it without
    executing its ``__init__``.
    """
    try:
        spec = importlib.util.find_spec("stable_retro")
    except (ImportError, ValueError):
        spec = None
    if spec is not None and spec.submodule_search_locations:
        return Path(next(iter(spec.submodule_search_locations)))
    from importlib import metadata  # a tenth of `retrokit --help`'s time, for this fallback only

    try:
        located = metadata.distribution("stable-retro").locate_file("stable_retro")
    except metadata.PackageNotFoundError:
        return None
    path = Path(str(located))
    return path if path.is_dir() else None


def wheel_cores_dir() -> Path | None:
    """Return the wheel's ``cores/`` folder (``*.json`` core info and libretro cores)."""
    root = wheel_dir()
    return root / "cores" if root is not None and (root / "cores").is_dir() else None


def wheel_data_dirs() -> list[Path]:
    """Return the wheel's integration folders that exist: stable, experimental, contrib."""
    root = wheel_dir()
    if root is None:
        return []
    return [root / "data" / kind for kind in WHEEL_DATA_KINDS if (root / "data" / kind).is_dir()]


def _bundled(copy: str, checkout: str) -> Path | None:
    """The package's copy of a top-level folder (an installed retrokit), else the checkout's folder, if either exists."""
    package = Path(__file__).resolve().parent
    for path in (package / copy, package.parent / checkout):
        if path.is_dir():
            return path
    return None


BUNDLED_GAMES = "_games"
"""The package folder an installed retrokit keeps the bundled ``games/`` in (``setup.py`` copies it there)."""


def repo_games_dir() -> Path | None:
    """Return the bundled integrations: ``games/`` of a checkout, or the copy inside an installed package."""
    return _bundled(BUNDLED_GAMES, "games")


BUNDLED_DOCS = "_docs"
"""The package folder an installed retrokit keeps ``docs/*.md`` in (``setup.py`` copies them there)."""


def docs_dir() -> Path | None:
    """Return the user guides: ``docs/`` of a checkout, or the copy inside an installed package."""
    return _bundled(BUNDLED_DOCS, "docs")


def doc_topics() -> list[str]:
    """Return the names of the guides ``retrokit docs TOPIC`` prints (``integrate`` for ``docs/integrate.md``)."""
    folder = docs_dir()
    return sorted(path.stem for path in folder.glob("*.md")) if folder is not None else []


def doc_path(topic: str) -> Path:
    """Return the guide named ``topic`` (``integrate``, ``integrate.md`` or ``docs/integrate.md``).

    Raises:
        UnknownNameError: No guide has that name (with a did-you-mean), or this install has no guides.
    """
    topics = doc_topics()
    name = topic.removeprefix("docs/").removesuffix(".md")
    if name not in topics:
        raise UnknownNameError(
            f"Expected one of retrokit's guides ({', '.join(topics) or 'none found in this install'}); "
            f"got {shown(topic)}. `retrokit docs` lists them." + did_you_mean(name, topics)
        )
    return docs_dir() / f"{name}.md"  # type: ignore[operator]


def env_games_dirs() -> list[Path]:
    """Return the folders named in ``RETROKIT_GAMES``, in order (existing or not)."""
    value = os.environ.get(GAMES_ENV, "")
    return [Path(part).expanduser() for part in value.split(os.pathsep) if part.strip()]


def game_search_dirs() -> list[Path]:
    """Return the existing folders that hold game folders, in search order."""
    candidates = [*env_games_dirs(), user_games_dir()]
    repo = repo_games_dir()
    if repo is not None:
        candidates.append(repo)
    candidates.extend(wheel_data_dirs())
    seen: set[Path] = set()
    result = []
    for path in candidates:
        if path.is_dir() and path not in seen:
            seen.add(path)
            result.append(path)
    return result


def _umask() -> int:
    """The process's umask, read without changing it where Linux tells it."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except OSError:
        pass
    umask = os.umask(0o022)  # elsewhere: set and restore at once
    os.umask(umask)
    return umask


REPLACE_HINT = "Choose another name, or ask to replace it (--force; overwrite=True from Python)."
"""How to get past a file in the way, unless a caller knows better: every command says ``--force``."""


def atomic_write(path: Path | str, data: bytes, *, overwrite: bool = False, hint: str = REPLACE_HINT) -> None:
    """Write ``data`` to ``path`` through a temporary file renamed into place.

    Readers never see a half-written file. With ``overwrite=False`` the final
    step is a hard link, which fails if ``path`` appeared meanwhile, so no file
    is ever replaced by accident.

    Args:
        path: The destination; its parent folders are created.
        data: The bytes to write.
        overwrite: Replace ``path`` if it exists.
        hint: How to get past a file in the way, for the error (by default :data:`REPLACE_HINT`).

    Raises:
        FileConflictError: ``path`` exists and ``overwrite`` is false (nothing is written).
        FileSystemError: The folder cannot be made or written (a file in its
            way, no permission, a read-only or full disk).
    """
    with atomic_output(path, overwrite=overwrite, hint=hint) as f:
        f.write(data)


@contextlib.contextmanager
def atomic_output(path: Path | str, *, overwrite: bool = False, hint: str = REPLACE_HINT) -> Iterator[BinaryIO]:
    """Open a temporary file beside ``path`` to write into; put it in place when the block ends.

    Like :func:`atomic_write`, for output written piece by piece (a long GIF)
    that should never be held in memory whole. If the block raises, the
    temporary file is deleted and ``path`` is left as it was.

    Raises:
        FileConflictError: ``path`` exists and ``overwrite`` is false: checked
            before the block runs (so no work is wasted) and again when the file
            is put in place.
        FileSystemError: The folder cannot be made or written.
    """
    path = Path(path)
    if not overwrite and os.path.lexists(path):
        raise _conflict(path, hint)
    ensure_folder(path.parent, f"to write {path.name} into")
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise _cannot(path.parent, f"to write {path.name} into", exc) from None
    tmp = Path(tmp_name)
    try:
        # mkstemp makes the file private (0600); give it the mode any new file gets.
        os.chmod(fd, 0o666 & ~_umask())
        with os.fdopen(fd, "wb") as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
        if overwrite:
            os.replace(tmp, path)
            return
        try:
            os.link(tmp, path)  # fails if path exists, unlike a rename
        except FileExistsError:
            raise _conflict(path, hint) from None
        except OSError:  # the file system has no hard links: check, then rename
            if os.path.lexists(path):
                raise _conflict(path, hint) from None
            os.replace(tmp, path)
    except (FileConflictError, FileSystemError):
        raise
    except OSError as exc:  # a full disk, a file system gone read-only meanwhile
        raise _cannot(path, "written", exc) from None
    finally:
        tmp.unlink(missing_ok=True)


_held = threading.local()  # the folders this thread holds the lock of, with how many times it took each
_thread_locks: dict[str, threading.Lock] = {}
_thread_locks_guard = threading.Lock()


@contextlib.contextmanager
def locked(path: Path | str) -> Iterator[None]:
    """Hold the lock of the folder that holds ``path`` for a read-modify-write of it.

    Every edit of a file others edit too (a game.yaml the CLI and two
    studios change at once) reads, changes and writes it inside this block,
    so no acknowledged edit is lost to a writer that read the file before
    it. The lock is the OS's (``flock``) on the folder itself, so it needs no
    lock file, leaves nothing behind and dies with its process; the folder
    is that of the file's target, so writers through a symlink and writers of
    the target share it. Threads of one process take a thread lock first
    (``flock`` is per open file, not per process), and a thread that holds
    the lock may take it again.

    Raises:
        FileSystemError: The folder cannot be opened to lock.
    """
    folder = os.path.dirname(os.path.realpath(path)) or "."
    depth = getattr(_held, "folders", None)
    if depth is None:
        depth = _held.folders = {}
    if depth.get(folder):  # this thread holds it already: an edit within an edit
        depth[folder] += 1
        try:
            yield
        finally:
            depth[folder] -= 1
        return
    with _thread_locks_guard:
        thread_lock = _thread_locks.setdefault(folder, threading.Lock())
    with thread_lock:
        try:
            fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0) | getattr(os, "O_CLOEXEC", 0))
        except OSError as exc:
            raise FileSystemError(
                f"Expected a folder at {folder!r} to lock while {os.path.basename(path)} is edited; found "
                f"{exc.strerror or exc}. Check the path and its permissions."
            ) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)  # waits for the other writer: each edit takes milliseconds
            depth[folder] = 1
            try:
                yield
            finally:
                depth[folder] = 0
        finally:
            os.close(fd)  # releases the flock


def _conflict(path: Path, hint: str) -> FileConflictError:
    """The error for a file in the way of a write that may not replace it."""
    kind = "a folder" if path.is_dir() else "a file"
    return FileConflictError(f"Expected no file at {str(path)!r}; found {kind} there, left as it is. {hint}")


def _cannot(path: Path, purpose: str, exc: OSError) -> FileSystemError:
    """The error for a folder that exists but cannot be written, or a file that cannot be."""
    reason = exc.strerror or str(exc)
    if purpose == "written":
        return FileSystemError(
            f"Expected to write {str(path)!r}; found it cannot be written: {reason}. "
            "Free some space, or choose another place."
        )
    return FileSystemError(
        f"Expected a writable folder at {str(path)!r} {purpose}; found it cannot be written: {reason}. "
        "Choose another place, or make the folder writable."
    )


def ensure_folder(folder: Path | str, purpose: str = "written") -> Path:
    """Create ``folder`` (and its parents) if needed; return it.

    Args:
        folder: The folder.
        purpose: What it is for, in the error message (``"to write x.gif into"``).

    Raises:
        FileSystemError: A file stands where the folder or one of its parents
            should be, or the folder cannot be created.
    """
    folder = Path(folder)
    if "\0" in str(folder):  # os refuses it with a ValueError, not an OSError
        raise FileSystemError(f"Expected a folder path {purpose}; found {str(folder)!r}, which holds a NUL byte. Remove it.")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:  # mkdir says FileExistsError for a file in the way: not a conflict, a wrong path
        if os.path.exists(folder):  # os.path's: False, not an error, for a name too long
            reason = "a file, not a folder"
        elif isinstance(exc, (FileExistsError, NotADirectoryError)):
            reason = "a file where one of its parent folders should be"
        else:
            reason = f"it cannot be made: {exc.strerror or exc}"
        raise FileSystemError(
            f"Expected a folder at {str(folder)!r} {purpose}; found {reason}. Choose another place, or move the file."
        ) from None
    return folder


def writable_folder(folder: Path | str, purpose: str) -> Path:
    """Make ``folder`` if needed and prove it can take a new file now; return it.

    For a folder used later (``make(record=...)`` records at each ``reset()``):
    the check is made up front, by creating and deleting a file in it, so that
    a file in the way, a name too long, or a folder under ``/proc`` is an
    error where the folder was given.

    Args:
        folder: The folder.
        purpose: What it is for, in the error message (``"to record movies into"``).

    Raises:
        FileSystemError: The folder cannot be made, or cannot be written.
    """
    folder = ensure_folder(folder, purpose)
    try:
        with tempfile.TemporaryFile(dir=folder, prefix=".retrokit-probe."):
            pass
    except OSError as exc:
        raise _cannot(folder, purpose, exc) from None
    return folder


def require_regular_file(path: Path | str, what: str) -> Path:
    """Return ``path`` if it is a regular file (symlinks followed).

    A FIFO would block a reader forever and a device (``/dev/zero``) never
    end, so neither is ever read as a data file.

    Args:
        path: The file.
        what: What it should be, for the error (``"a .bk2 movie"``).

    Raises:
        FileSystemError: ``path`` is missing, a folder, a device, a FIFO or a socket.
    """
    path = Path(path)
    try:
        mode = path.stat().st_mode
    except OSError as exc:
        raise FileSystemError(f"Expected {what} at {str(path)!r}; found {exc.strerror or exc}.") from None
    if not stat.S_ISREG(mode):
        raise _not_regular(path, what, mode)
    return path


def _not_regular(path: Path, what: str, mode: int) -> FileSystemError:
    """The error for a path that is not a regular file (``mode`` from its stat)."""
    kind = "a folder" if stat.S_ISDIR(mode) else "a FIFO" if stat.S_ISFIFO(mode) else "a device or socket"
    return FileSystemError(
        f"Expected {what} at {str(path)!r}; found {kind}, which is not a file retrokit reads. "
        "Replace it with a regular file, or remove it."
    )


def read_regular_file(path: Path | str, what: str, limit: int, *, follow: bool = True) -> bytes:
    """Read a data file whole: the one guarded way retrokit reads a game's files.

    The file is opened with ``O_NONBLOCK``, so a FIFO cannot block the open,
    then checked on the open descriptor (no race with a rename): only a
    regular file is read, and never more than ``limit`` bytes, so a link to
    ``/dev/zero`` or a huge file cannot fill memory.

    Args:
        path: The file (symlinks followed; a loop is an error).
        what: What it should be, for the error (``"a game.yaml data file"``).
        limit: The most bytes a file of this kind may hold.
        follow: Follow a symlink at ``path`` itself (else it is an error, as for a record: :func:`records_dir`).

    Raises:
        FileSystemError: ``path`` is missing, unreadable, a symlink loop, a folder,
            a device, a FIFO or a socket, or larger than ``limit``.
    """
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC | (0 if follow else os.O_NOFOLLOW))
    except OSError as exc:
        found = ("a symlink loop" if follow else "a symlink") if exc.errno == errno.ELOOP else exc.strerror or str(exc)
        raise FileSystemError(f"Expected {what} at {str(path)!r}; found {found}. Fix or remove it.") from None
    try:
        mode = os.fstat(fd).st_mode
        chunks = []
        size = 0
        while stat.S_ISREG(mode) and size <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as exc:  # EIO on a failing disk
        raise FileSystemError(f"Expected {what} at {str(path)!r}; found it cannot be read: {exc.strerror or exc}.") from None
    finally:
        os.close(fd)
    if not stat.S_ISREG(mode):
        raise _not_regular(path, what, mode)
    if size > limit:
        raise FileSystemError(
            f"Expected {what} at {str(path)!r} of at most {_size(limit)}; found a larger file. Is it the right file?"
        )
    return b"".join(chunks)


def _size(count: int) -> str:
    """A byte count as people write it: ``4 MiB``, ``1 KiB``, or bytes."""
    for unit, scale in (("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if count >= scale and count % scale == 0:
            return f"{count // scale} {unit}"
    return f"{count} bytes"
