"""The run folder: what an evaluation has done so far, and how ``--resume`` reads it back.

``run.json`` holds the evaluation's settings and the levels finished so far;
``episodes.jsonl`` one line per finished episode. A level counts once it is
finished; on ``--resume`` the episodes of unfinished levels are dropped and
those levels start again from their seed, so the result equals an
uninterrupted run. Each episode line is flushed as it comes, and ``run.json``
is replaced atomically after it, so a killed run leaves a readable folder.

A run holds an OS lock on ``run.lock`` for its lifetime (it dies with the
process), so a second run on the same folder is refused; the file is removed
when the run ends (a killed run leaves it, unlocked, for the next to take). Everything read back
is checked: a damaged folder ends in one :class:`~retrokit.errors.RunFolderError`.
"""

from __future__ import annotations

import fcntl
import json
import math
import os
import stat
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, BinaryIO

from retrokit.benchmark.monitor import Episode
from retrokit.errors import FileConflictError, RetrokitError, RunFolderError
from retrokit.paths import atomic_write, ensure_folder

RUN_FILE = "run.json"
EPISODES_FILE = "episodes.jsonl"
LOCK_FILE = "run.lock"
OUTPUTS = (RUN_FILE, EPISODES_FILE, "summary.json", "summary.csv", "report.md")
MAX_RUN_FILE_BYTES = 16 << 20  # settings and one entry per level: a few kB
MAX_LINE_BYTES = 1 << 16  # an episode line is about 120 bytes


@dataclass(frozen=True)
class FinishedLevel:
    """A level that spent its budget.

    Attributes:
        timesteps: Its timesteps (the budget).
        episodes: Its finished episodes, all in ``episodes.jsonl``.
        unfinished_reward: The reward of the episode under way when the budget ran out.
    """

    timesteps: int
    episodes: int
    unfinished_reward: float = 0.0

    @classmethod
    def from_json(cls, data: Any) -> FinishedLevel:
        """Read an entry of ``run.json``'s ``finished``.

        Raises:
            ValueError: It is not of that shape (the message says how).
        """
        if not isinstance(data, dict):
            raise ValueError(f"a finished level must be a mapping, got {type(data).__name__}")  # noqa: TRY004 - bad data
        values = [data.get("timesteps"), data.get("episodes")]
        if any(not isinstance(v, int) or isinstance(v, bool) or v < 0 for v in values):
            raise ValueError(f"'timesteps' and 'episodes' must be whole numbers of 0 or more, got {values}")
        reward = data.get("unfinished_reward", 0.0)
        if not isinstance(reward, int | float) or isinstance(reward, bool) or not math.isfinite(reward):
            raise ValueError(f"'unfinished_reward' must be a finite number, got {reward!r}")
        return cls(values[0], values[1], float(reward))


class RunDir:
    """An evaluation's output folder, locked while this object is open.

    Args:
        path: The folder.
        settings: What determines the results (benchmark, agent, seed, budget, levels).
        resume: Continue the evaluation the folder holds, which must have the same settings.

    Raises:
        FileConflictError: Without ``resume``, the folder already holds an evaluation.
        RunFolderError: With ``resume``, it holds none, a damaged one, or one with other settings;
            or another run is using the folder.
    """

    def __init__(self, path: str | os.PathLike[str], settings: dict[str, Any], *, resume: bool) -> None:
        self.path = Path(path)
        self.settings = settings
        self.budget: int = settings["budget"]
        self.finished: dict[str, FinishedLevel] = {}
        self.failed: dict[str, str] = {}
        self.episodes: dict[str, list[Episode]] = {}
        self.replayed: list[str] = []  # finished levels of an older run that did not spend their budget
        self._lock = claim_folder(self.path, OUTPUTS, "evaluation", resume=resume)
        try:
            if resume:
                self._load()
            else:
                self._save()
                atomic_write(self.path / EPISODES_FILE, b"", overwrite=True)
            self._log = open(self.path / EPISODES_FILE, "a", encoding="utf-8")  # noqa: SIM115 - open for the run
        except BaseException:
            os.close(self._lock)
            raise

    def _damaged(self, name: str, problem: str) -> RunFolderError:
        return _damaged(self.path, name, problem)

    def _load(self) -> None:
        saved = read_run_file(self.path)
        check_same_settings(self.path, saved["settings"], self.settings)
        for level, data in saved["finished"].items():
            try:
                entry = FinishedLevel.from_json(data)
            except ValueError as exc:
                raise self._damaged(RUN_FILE, f"its level {level}: {exc}") from None
            if level not in self.settings["levels"] or entry.timesteps > self.budget:
                raise self._damaged(RUN_FILE, f"its level {level} is not of this run or played more than its budget")
            if entry.timesteps < self.budget:
                self.replayed.append(level)  # an older retrokit called a level that returned early finished
            else:
                self.finished[level] = entry
        kept = self._read_episodes()
        for level, entry in self.finished.items():
            numbers = [episode.episode for episode in self.episodes.get(level, ())]
            if numbers != list(range(1, entry.episodes + 1)):
                raise RunFolderError(
                    f"Expected episodes 1 to {entry.episodes} of the finished level {level} in {EPISODES_FILE}, "
                    f"found {len(numbers)}; the folder was changed by hand. Start in a new --out."
                )
        atomic_write(self.path / EPISODES_FILE, "".join(line + "\n" for line in kept).encode(), overwrite=True)

    def _read_episodes(self) -> list[str]:
        """Read the episodes of the finished levels; return their lines, to keep."""
        kept: list[str] = []
        if not os.path.lexists(self.path / EPISODES_FILE):
            return kept
        with self._open(EPISODES_FILE) as f:
            number = 0
            while line := f.readline(MAX_LINE_BYTES + 1):
                number += 1
                if len(line) > MAX_LINE_BYTES:
                    raise self._damaged(EPISODES_FILE, f"its line {number} is longer than {MAX_LINE_BYTES} bytes")
                try:
                    record = json.loads(line.decode("utf-8"))
                except (UnicodeDecodeError, ValueError, RecursionError):
                    if not line.endswith(b"\n"):
                        break  # the half-written last line of a killed run
                    raise self._damaged(EPISODES_FILE, f"its line {number} is not JSON") from None
                level = record.get("level") if isinstance(record, dict) else None
                if not isinstance(level, str):
                    raise self._damaged(EPISODES_FILE, f"its line {number} names no level")
                if level in self.finished:
                    try:
                        episode = Episode.from_record(record, self.budget)
                    except ValueError as exc:
                        raise self._damaged(EPISODES_FILE, f"its line {number}: {exc}") from None
                    self.episodes.setdefault(level, []).append(episode)
                    kept.append(json.dumps(episode.record(level)))
        return kept

    def _open(self, name: str) -> BinaryIO:
        return _open(self.path, name)

    def _save(self) -> None:
        data = {"settings": self.settings, "finished": {k: asdict(v) for k, v in self.finished.items()},
                "failed": self.failed}
        atomic_write(self.path / RUN_FILE, (json.dumps(data, indent=1) + "\n").encode(), overwrite=True)

    def add_episode(self, level: str, episode: Episode) -> None:
        """Log a finished episode."""
        self._log.write(json.dumps(episode.record(level)) + "\n")
        self._log.flush()
        self.episodes.setdefault(level, []).append(episode)

    def finish(self, level: str, timesteps: int, unfinished_reward: float) -> None:
        """Mark a level finished: its episodes so far are its result."""
        self.failed.pop(level, None)
        self.finished[level] = FinishedLevel(timesteps, len(self.episodes.get(level, ())), unfinished_reward)
        self._save()

    def restart(self, level: str) -> None:
        """Drop the episodes of an unfinished level that plays again from its beginning (its machine was lost).

        The log is rewritten without them, as ``--resume`` rewrites it, so the level's replay logs its episodes
        from the first again.
        """
        if level in self.finished or not self.episodes.pop(level, None):
            return
        kept = [json.dumps(episode.record(name)) for name, episodes in self.episodes.items() for episode in episodes]
        self._log.close()
        atomic_write(self.path / EPISODES_FILE, "".join(line + "\n" for line in kept).encode(), overwrite=True)
        self._log = open(self.path / EPISODES_FILE, "a", encoding="utf-8")  # noqa: SIM115 - open for the run

    def fail(self, level: str, error: str) -> None:
        """Note why a level failed (it will start again on --resume); its episodes are dropped then."""
        self.failed[level] = error
        self._save()

    def close(self) -> None:
        """Close the episode log and release the folder, removing its lock file."""
        self._log.close()
        unlock_folder(self.path / LOCK_FILE, self._lock)


def unlock_folder(path: Path, fd: int) -> None:
    """Release a run folder's lock that :func:`lock_folder` took on ``path`` (``fd``), removing the lock file.

    It is unlinked while still held: a run that opened the old file meanwhile sees it is no longer the path's
    file once it gets the lock, and takes the new one (see :func:`lock_folder`), so two runs never both hold the
    folder.
    """
    try:
        path.unlink()
    except FileNotFoundError:
        pass
    os.close(fd)


def claim_folder(path: Path, outputs: tuple[str, ...], kind: str, *, resume: bool) -> int:
    """Take a run folder for a run of ``kind``: a new (or empty) one, or with ``resume`` one that holds such a run.

    Args:
        path: The folder.
        outputs: The files a run of this kind writes; the first is its settings file, which a run to resume has.
        kind: ``"evaluation"``, ``"training run"``: for the messages.
        resume: Continue the run there.

    Returns:
        The lock's descriptor (see :func:`lock_folder`; :func:`unlock_folder` releases it).

    Raises:
        RunFolderError: With ``resume``, the folder holds no run; or another run holds its lock.
        FileConflictError: Without ``resume``, the folder holds a run's outputs already.
    """
    what = f"{'an' if kind[0] in 'aeiou' else 'a'} {kind}"
    run_file = path / outputs[0]
    if resume and not run_file.exists() and not run_file.is_symlink():
        raise RunFolderError(
            f"Expected {path} to hold {what} to resume ({outputs[0]}), but it has none; drop --resume to start one."
        )
    if not resume:
        refuse_earlier(path, outputs, what)
        ensure_folder(path, f"for the {kind}'s results")
    fd = lock_folder(path / LOCK_FILE, kind)
    if not resume:
        try:
            refuse_earlier(path, outputs, what)  # again, now that no other run can be writing
        except BaseException:
            os.close(fd)
            raise
    return fd


def refuse_earlier(path: Path, outputs: tuple[str, ...], what: str) -> None:
    """Refuse a new run in a folder that holds one of a run's ``outputs`` already.

    Args:
        path: The run folder.
        outputs: The files a run of this kind writes.
        what: The kind of run, for the message (``"an evaluation"``).

    Raises:
        FileConflictError: One of them is there.
    """
    there = [name for name in outputs if os.path.lexists(path / name)]
    if there:
        raise FileConflictError(
            f"Expected a new or empty --out folder, but {path} already holds {what} "
            f"({', '.join(there)}); continue it with --resume, or choose another --out."
        )


def check_same_settings(path: Path, saved: dict[str, Any], settings: dict[str, Any]) -> None:
    """Refuse to resume the run in ``path``, started with ``saved``, with other ``settings``.

    Raises:
        RunFolderError: They differ; the message names the keys that do.
    """
    if saved != settings:
        differ = sorted(k for k in {*saved, *settings} if saved.get(k) != settings.get(k))
        raise RunFolderError(
            f"Expected --resume with the settings {path} was started with, but {', '.join(map(str, differ))} "
            "differ; use the same options, or a new --out."
        )


def lock_folder(path: Path, what: str = "evaluation") -> int:
    """Take a run folder's lock (released when the descriptor closes or the process dies); return the descriptor.

    A run that ends removes the lock file while it still holds it; the lock
    taken is on the file that is at ``path`` once taken, not on one removed
    meanwhile.

    Raises:
        RunFolderError: Another run holds it, or the lock file cannot be made.
    """
    for _ in range(100):
        fd = _lock_once(path, what)
        try:
            held, there = os.fstat(fd), os.stat(path, follow_symlinks=False)
        except FileNotFoundError:
            there = None
        if there is not None and (held.st_dev, held.st_ino) == (there.st_dev, there.st_ino):
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
            return fd
        os.close(fd)  # removed by the run that held it, after we opened it: lock the file there now
    raise RunFolderError(f"Expected to lock {path} for this run, but it kept being replaced; use another --out.")


def _nothing_to_resume(folder: Path) -> RunFolderError:
    return RunFolderError(
        f"Expected {folder} to hold an evaluation to resume ({RUN_FILE}), but it has none; drop --resume to start one."
    )


def _damaged(folder: Path, name: str, problem: str) -> RunFolderError:
    return RunFolderError(
        f"Expected a readable {folder / name} to resume, but {problem}; the folder is damaged: start in a new --out."
    )


def _open(folder: Path, name: str) -> BinaryIO:
    """Open one of a run folder's files for reading: a regular file only (a FIFO would block, a device never end)."""
    try:
        fd = os.open(folder / name, os.O_RDONLY | os.O_NONBLOCK)
    except OSError as exc:
        raise _damaged(folder, name, f"it cannot be opened ({exc.strerror or exc})") from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise _damaged(folder, name, "it is not a regular file (a FIFO, a device or a folder)")
    return os.fdopen(fd, "rb")


def read_run_file(folder: Path) -> dict[str, Any]:
    """The ``run.json`` of a run folder: its ``settings`` and ``finished`` mappings, checked for that shape.

    Raises:
        RunFolderError: It is missing, unreadable, too large, not JSON, or not of that shape.
    """
    if not os.path.lexists(folder / RUN_FILE):
        raise _nothing_to_resume(folder)
    with _open(folder, RUN_FILE) as f:
        raw = f.read(MAX_RUN_FILE_BYTES + 1)
    if len(raw) > MAX_RUN_FILE_BYTES:
        raise _damaged(folder, RUN_FILE, f"it is larger than {MAX_RUN_FILE_BYTES >> 20} MB")
    try:
        saved = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise _damaged(folder, RUN_FILE, f"it is not JSON ({type(exc).__name__})") from None
    if not isinstance(saved, dict) or not isinstance(saved.get("settings"), dict) \
            or not isinstance(saved.get("finished"), dict):
        raise _damaged(folder, RUN_FILE, "it does not map 'settings' and 'finished' to mappings")
    return saved


def _lock_once(path: Path, what: str) -> int:
    """Open ``path`` and take its lock; return the descriptor."""
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC, 0o644)
    except OSError as exc:
        raise RunFolderError(
            f"Expected to lock {path} for this run, but it cannot be opened ({exc.strerror or exc}); "
            "remove it if it is not a file, or use another --out."
        ) from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise RunFolderError(f"Expected {path} to be a lock file, but it is not a regular file; remove it.")
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip()
            who = f"process {holder}" if holder.isdigit() else "a process that has not written its number yet"
            raise RunFolderError(
                f"Expected no other {what} running in the folder {str(path.parent)!r}; found one there ({who}). "
                "Wait for it to end, or use another --out."
            ) from None
    except (RetrokitError, OSError):
        os.close(fd)
        raise
    return fd
