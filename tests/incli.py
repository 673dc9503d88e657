"""The command line run in the test's own process, answering as ``subprocess.run`` of ``python -m retrokit`` would.

For tests about what a command prints and writes, not about processes: each command still starts from the
files alone (a ramsearch session is loaded from and saved to its file per command), without the second of
interpreter start and imports a child costs. Tests about signals, kills, exit codes of a crashed or killed
process or leftover processes keep their children (tests/childproc.py).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import shutil
import subprocess
import sys
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


#: Forks one child per command, all before waiting for any, from one interpreter that imported ``warm`` first.
_FORKING = """
import importlib, json, os, sys
from retrokit import cli
argvs, folder, warm, prime = json.loads(sys.argv[1]), sys.argv[2], json.loads(sys.argv[3]), json.loads(sys.argv[4])
for module in warm:
    importlib.import_module(module)
if prime:  # a read-only command fills the caches every command would fill (wheel listing, game folders) once
    with open(os.devnull, "w") as nowhere:
        sys.stdout, sys.stderr = nowhere, nowhere
        primed = cli.main(prime)
        sys.stdout, sys.stderr = sys.__stdout__, sys.__stderr__
    assert primed == 0, f"the priming command {prime} failed ({primed})"
pids = []
for n, argv in enumerate(argvs):
    pid = os.fork()
    if pid == 0:
        status = 70
        try:
            with open(f"{folder}/{n}.out", "w") as out, open(f"{folder}/{n}.err", "w") as err:
                sys.stdout, sys.stderr = out, err
                status = cli.main(argv)
        finally:
            os._exit(status)
    pids.append(pid)
print(json.dumps([os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1]) for pid in pids]))
"""


def retrokit_at_once(
    cwd: Path, argvs: list[list[str]], env: dict[str, str], warm: tuple[str, ...] = (), prime: list[str] | None = None
) -> list[subprocess.CompletedProcess]:
    """Run ``retrokit ARGV...`` for each argv in its own process, all at once; return each as a finished child.

    For tests about processes racing on files: the children are forked, all before any is waited for, from one
    interpreter that imported ``warm`` (modules) first and ran the read-only command ``prime``, if given, so what
    races is the commands' work, not imports and first-use caches.
    """
    folder = cwd / ".at-once"
    folder.mkdir()
    done = subprocess.run(
        [sys.executable, "-c", _FORKING, json.dumps(argvs), str(folder), json.dumps(list(warm)), json.dumps(prime or [])],
        cwd=cwd, env=env, capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    statuses = json.loads(done.stdout)
    answers = [
        subprocess.CompletedProcess(["retrokit", *argv], status, (folder / f"{n}.out").read_text(),
                                    (folder / f"{n}.err").read_text())
        for n, (argv, status) in enumerate(zip(argvs, statuses, strict=True))
    ]  # fmt: skip
    shutil.rmtree(folder)
    return answers
