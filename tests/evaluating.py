"""Helpers of the evaluate tests: small runs on Dasher, agent files the tests write, and a scan for leftover processes."""

from __future__ import annotations

import os
import time
from pathlib import Path

from retrokit.cli import main

TWO_LEVELS = "Zone2.Act2,Zone3.Act2"
# 300 timesteps: JERK ends 1 episode on Zone2.Act2 and 8 on Zone3.Act2, enough lines for a run to be stopped
# between them, and a resume test's JERK (which waits at its 200th step) still stops mid-level.
SMALL = ["--benchmark", "dasher", "--levels", TWO_LEVELS, "--timesteps", "300", "--no-progress"]


def evaluate(out: Path, *args: str) -> int:
    """``retrokit evaluate`` on two Dasher levels, 300 timesteps each (later options win), into ``out``."""
    return main(["evaluate", *SMALL, "--out", str(out), *args])


def write_agents(folder: Path, source: str, name: str = "my_agents.py") -> Path:
    """Write agents' source into ``folder/name``; return the file."""
    path = folder / name
    path.write_text(source)
    return path


def session_processes(session: int) -> list[int]:
    """The live (not zombie) processes of a session, read from /proc."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            text = Path(f"/proc/{entry}/stat").read_text()
        except OSError:
            continue  # it ended while we looked
        fields = text[text.rindex(")") + 2:].split()  # state, ppid, pgrp, session, ...
        if int(fields[3]) == session and fields[0] != "Z":
            found.append(int(entry))
    return found


def wait_for(condition, timeout: float, what: str) -> None:
    """Wait until ``condition()`` is true, or fail naming ``what``."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"still waiting after {timeout} s for {what}")
        time.sleep(0.05)
