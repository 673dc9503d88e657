"""Running a hostile input in a child process, so a regression fails a test instead of killing or hanging the suite.

The child runs a snippet of Python under a wall-clock timeout and an address
space limit; it prints its peak resident memory (``VmHWM``) on its last
line, so a test can hold it to the 500 MB every input must stay under.
"""

from __future__ import annotations

import json
import os
import resource
import signal
import subprocess
import sys
import textwrap
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
MAX_RSS_MB = 500
ADDRESS_SPACE = 3 * 2**30  # far above what Python, numpy and a core map, far below what a blow-up wants
_MARK = "childproc-peak-rss-kb:"
# The child's own peak: VmHWM belongs to its address space, which exec made anew. (ru_maxrss is
# not: Linux carries it across fork and exec, so a child of a big pytest process would report
# the parent's peak.) Elsewhere, ru_maxrss is the best there is.
_PEAK_KB = (
    "next((int(l.split()[1]) for l in open('/proc/self/status') if l.startswith('VmHWM:')), 0) "
    "if __import__('os').path.exists('/proc/self/status') "
    "else __import__('resource').getrusage(__import__('resource').RUSAGE_SELF).ru_maxrss"
)


@dataclass
class Child:
    """How a child ended."""

    returncode: int
    stdout: str
    stderr: str
    peak_rss_mb: float

    @property
    def signal(self) -> str | None:
        """The signal that killed the child (``"SIGSEGV"``), or ``None``."""
        return signal.Signals(-self.returncode).name if self.returncode < 0 else None

    def describe(self) -> str:
        """Everything a failing assertion should show."""
        return f"exit {self.returncode} ({self.signal}), peak {self.peak_rss_mb:.0f} MB\n{self.stdout}\n{self.stderr}"


def _limits() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))  # a crash must leave no core file


def run_child(code: str, *, timeout: float = 60, env: dict[str, str] | None = None, cwd: Path | None = None) -> Child:
    """Run ``code`` in a fresh interpreter; return how it ended and its peak RSS.

    A child still running after ``timeout`` seconds is killed, and the test
    fails with a clear message rather than hanging.
    """
    script = textwrap.dedent(code) + f"\nprint({_MARK!r}, {_PEAK_KB}, flush=True)\n" + (
        "raise SystemExit(globals().get('exit_status', 0))\n"
    )
    try:
        done = subprocess.run(
            [sys.executable, "-c", script], capture_output=True, text=True, errors="replace", timeout=timeout, check=False,
            env={**os.environ, **(env or {})}, cwd=cwd or REPO, preexec_fn=_limits, stdin=subprocess.DEVNULL,
        )
    except subprocess.TimeoutExpired as exc:
        raise AssertionError(f"the child hung: still running after {timeout} s\n{exc.stdout}\n{exc.stderr}") from None
    peak = 0.0
    lines = []
    for line in done.stdout.splitlines():
        if line.startswith(_MARK):
            peak = int(line.split()[-1]) / 1024
        else:
            lines.append(line)
    return Child(done.returncode, "\n".join(lines), done.stderr, peak)


def run_cli(args: list[str], *, timeout: float = 60, env: dict[str, str] | None = None, cwd: Path | None = None) -> Child:
    """Run ``retrokit ARGS...`` in a child process."""
    return run_child(f"from retrokit.cli import main\nexit_status = main({args!r})", timeout=timeout, env=env, cwd=cwd)


#: Runs each case's command in turn, its environment updated by the case's, and prints each answer as it ends.
_CASES = """
import contextlib, io, json, os, traceback
from retrokit.cli import main
for name, argv, env in CASES:
    os.environ.update(env)
    with contextlib.redirect_stdout(io.StringIO()) as out, contextlib.redirect_stderr(io.StringIO()) as err:
        try:
            status = main(argv)
        except BaseException:  # what an uncaught error does to a command run alone: a traceback and status 1
            traceback.print_exc()
            status = 1
    print(ANSWER, json.dumps([name, status, out.getvalue(), err.getvalue()]), flush=True)
"""
_ANSWER = "childproc-case-answer:"


def run_cli_cases(
    cases: dict[str, list[str]], *, timeout: float = 120, env: dict[str, str] | None = None,
    case_env: dict[str, dict[str, str]] | None = None,
) -> dict[str, Child]:
    """Run ``retrokit ARGS...`` for each case in turn in ONE child, under the same limits as :func:`run_child`.

    For several hostile inputs whose outcomes are checked one by one: a child's start and imports cost more
    than most refusals. Each case's answer is a :class:`Child` of its own status, stdout and stderr, with the
    child's peak memory (which bounds each command's). A case the child never answered (it crashed or hung
    on an earlier one, or on this one) gets the child's own ending and output, so its test fails with them.

    Args:
        cases: Each case's name and command-line arguments.
        timeout: Seconds for all the cases together.
        env: Environment variables for the child.
        case_env: Environment variables set before a case's command (e.g. its own RETROKIT_DATA).
    """
    return run_cli_cases_in_child(cases, timeout=timeout, env=env, case_env=case_env)[0]


def run_cli_cases_in_child(
    cases: dict[str, list[str]], *, timeout: float = 120, env: dict[str, str] | None = None,
    case_env: dict[str, dict[str, str]] | None = None, cwd: Path | None = None,
) -> tuple[dict[str, Child], Child]:
    """:func:`run_cli_cases`'s answers, and the child itself: its own stderr holds what processes under it
    (an evaluation's workers) wrote to the terminal, which no case's redirected stderr catches."""
    runs = [(name, argv, (case_env or {}).get(name, {})) for name, argv in cases.items()]
    child = run_child(f"CASES = {runs!r}\nANSWER = {_ANSWER!r}\n" + _CASES, timeout=timeout, env=env, cwd=cwd)
    answers: dict[str, Child] = {}
    rest = []
    for line in child.stdout.splitlines():
        if line.startswith(_ANSWER):
            name, status, out, err = json.loads(line[len(_ANSWER):])
            answers[name] = Child(status, out, err, child.peak_rss_mb)
        else:
            rest.append(line)
    ended = Child(child.returncode or 1, "\n".join(rest), child.stderr, child.peak_rss_mb)
    return {name: answers.get(name, ended) for name in cases}, child
