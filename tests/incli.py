"""The command line run in the test's own process, answering as ``subprocess.run`` of ``python -m retrokit`` would.

For tests about what a command prints and writes, not about processes: each command still starts from the
files alone (a ramsearch session is loaded from and saved to its file per command), without the second of
interpreter start and imports a child costs. Tests about signals, kills, exit codes of a crashed or killed
process or leftover processes keep their children (tests/childproc.py).
"""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
from pathlib import Path

from retrokit import cli


def retrokit_in_process(cwd: Path, *argv: str) -> subprocess.CompletedProcess:
    """Run ``retrokit ARGV...`` in ``cwd``; return its status, stdout and stderr as a finished child's."""
    out, err = io.StringIO(), io.StringIO()
    before = os.getcwd()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            status = cli.main(list(argv))
    finally:
        os.chdir(before)
    return subprocess.CompletedProcess(["retrokit", *argv], status, out.getvalue(), err.getvalue())
