"""The run folder's lock: one evaluation at a time, and no run.lock left behind once it ends."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from retrokit.benchmark import rundir
from retrokit.benchmark.rundir import LOCK_FILE, RunDir
from retrokit.errors import RunFolderError

SETTINGS = {"benchmark": "dasher", "agent": "random", "seed": 0, "budget": 10, "levels": ["Dasher-Genesis/Zone1.Act2"]}


def test_the_lock_file_is_there_while_a_run_holds_the_folder_and_gone_after(tmp_path: Path) -> None:
    out = tmp_path / "run"
    run = RunDir(out, SETTINGS, resume=False)
    assert (out / LOCK_FILE).is_file()
    with pytest.raises(RunFolderError, match="Expected no other evaluation running"):
        RunDir(out, SETTINGS, resume=True)
    run.close()
    assert not (out / LOCK_FILE).exists()
    again = RunDir(out, SETTINGS, resume=True)  # the folder is free once the run ended
    again.close()
    assert sorted(p.name for p in out.iterdir()) == ["episodes.jsonl", "run.json"]


def test_a_run_that_opened_the_lock_file_as_its_holder_removed_it_locks_the_new_one(tmp_path, monkeypatch) -> None:
    out = tmp_path / "run"
    first = RunDir(out, SETTINGS, resume=False)
    real = rundir._lock_once
    raced = []

    def opened_before_the_first_run_ended(path: Path, what: str) -> int:
        if not raced:  # this run opened the old file; the first run then removed it and let go
            stale = os.open(path, os.O_RDWR)
            first.close()
            raced.append(stale)
            return stale  # its lock is free now, but on a file no longer at the path
        return real(path, what)

    monkeypatch.setattr(rundir, "_lock_once", opened_before_the_first_run_ended)
    second = RunDir(out, SETTINGS, resume=True)
    lock = out / LOCK_FILE
    assert lock.is_file() and os.fstat(second._lock).st_ino == lock.stat().st_ino
    monkeypatch.setattr(rundir, "_lock_once", real)
    with pytest.raises(RunFolderError, match="Expected no other evaluation running"):
        RunDir(out, SETTINGS, resume=True)  # a third run finds the folder held, by the file that is there
    second.close()
