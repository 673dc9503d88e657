"""The run folder: what an evaluation has done so far, and how ``--resume`` reads it back.

``run.json`` holds the evaluation's settings and the levels finished so far;
``episodes.jsonl`` one line per finished episode. A level counts once it is
finished; on ``--resume`` the episodes of unfinished levels are dropped and
those levels start again from their seed, so the result equals an
uninterrupted run. Each episode line is flushed as it comes, and ``run.json``
is replaced atomically after it, so a killed run leaves a readable folder.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from retrokit.errors import FileConflictError, RunFolderError
from retrokit.paths import atomic_write, ensure_folder

RUN_FILE = "run.json"
EPISODES_FILE = "episodes.jsonl"
OUTPUTS = (RUN_FILE, EPISODES_FILE, "summary.json", "summary.csv", "report.md")


class RunDir:
    """An evaluation's output folder.

    Args:
        path: The folder.
        settings: What determines the results (benchmark, agent, seed, budget, levels).
        resume: Continue the evaluation the folder holds, which must have the same settings.

    Raises:
        FileConflictError: Without ``resume``, the folder already holds an evaluation.
        RunFolderError: With ``resume``, it holds none, or one with other settings.
    """

    def __init__(self, path: str | os.PathLike[str], settings: dict[str, Any], *, resume: bool) -> None:
        self.path = Path(path)
        self.settings = settings
        self.finished: dict[str, dict[str, Any]] = {}
        self.failed: dict[str, str] = {}
        self.episodes: dict[str, list[dict[str, Any]]] = {}
        run_file = self.path / RUN_FILE
        if resume:
            self._load(run_file)
        else:
            there = [name for name in OUTPUTS if (self.path / name).exists()]
            if there:
                raise FileConflictError(
                    f"Expected a new or empty --out folder, but {self.path} already holds an evaluation "
                    f"({', '.join(there)}); continue it with --resume, or choose another --out."
                )
            ensure_folder(self.path, "for the evaluation's results")
            self._save()
            atomic_write(self.path / EPISODES_FILE, b"", overwrite=True)
        self._log = open(self.path / EPISODES_FILE, "a", encoding="utf-8")  # noqa: SIM115 - open for the run

    def _load(self, run_file: Path) -> None:
        try:
            saved = json.loads(run_file.read_text(encoding="utf-8"))
            settings, finished = saved["settings"], saved["finished"]
        except FileNotFoundError:
            raise RunFolderError(
                f"Expected {self.path} to hold an evaluation to resume ({RUN_FILE}), but it has none; "
                "drop --resume to start one."
            ) from None
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise RunFolderError(f"Expected a readable {run_file}, but it is damaged ({exc}); start in a new --out.") from None
        if settings != self.settings:
            differ = sorted(k for k in {*settings, *self.settings} if settings.get(k) != self.settings.get(k))
            raise RunFolderError(
                f"Expected --resume with the settings {self.path} was started with, but {', '.join(differ)} differ; "
                "use the same options, or a new --out."
            )
        self.finished = {level: dict(data) for level, data in finished.items()}
        kept: list[str] = []
        try:
            lines = (self.path / EPISODES_FILE).read_text(encoding="utf-8").splitlines()
        except FileNotFoundError:
            lines = []
        for line in lines:
            try:
                record = json.loads(line)
                level = record["level"]
            except (ValueError, KeyError, TypeError):
                continue  # the half-written last line of a killed run
            if level in self.finished:
                self.episodes.setdefault(level, []).append(record)
                kept.append(json.dumps(record))
        for level, data in self.finished.items():
            if len(self.episodes.get(level, ())) != data.get("episodes", 0):
                raise RunFolderError(
                    f"Expected {data.get('episodes')} episodes of the finished level {level} in {EPISODES_FILE}, "
                    f"found {len(self.episodes.get(level, ()))}; the folder was changed by hand. Start in a new --out."
                )
        atomic_write(self.path / EPISODES_FILE, "".join(line + "\n" for line in kept).encode(), overwrite=True)

    def _save(self) -> None:
        data = {"settings": self.settings, "finished": self.finished, "failed": self.failed}
        atomic_write(self.path / RUN_FILE, (json.dumps(data, indent=1) + "\n").encode(), overwrite=True)

    def add_episode(self, record: dict[str, Any]) -> None:
        """Log a finished episode."""
        self._log.write(json.dumps(record) + "\n")
        self._log.flush()
        self.episodes.setdefault(record["level"], []).append(record)

    def finish(self, level: str, timesteps: int) -> None:
        """Mark a level finished: its episodes so far are its result."""
        self.failed.pop(level, None)
        self.finished[level] = {"timesteps": timesteps, "episodes": len(self.episodes.get(level, ()))}
        self._save()

    def fail(self, level: str, error: str) -> None:
        """Note why a level failed (it will start again on --resume)."""
        self.failed[level] = error
        self._save()

    def close(self) -> None:
        """Close the episode log."""
        self._log.close()
