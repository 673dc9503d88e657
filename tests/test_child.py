"""The one runner of risky children (retrokit.host.child): limits, request, deadlines, a killed group, a failed start.

The core probe and the state probe both run through it; their own tests
(test_hostile_cores.py, test_hostile_states.py, test_validate.py) show the
verdicts. These show the runner's promises on a child of the test's own.
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import pytest
from childproc import run_child

from retrokit.errors import ChildStartError
from retrokit.host.child import Child

MODULE = "house_child"
CHILD = """
import json, os, resource, subprocess, sys, time
from retrokit.host.child import answer_channel, read_request

request = read_request()
answer = answer_channel(request)
if request["do"] == "limits":
    limits = {"as": resource.getrlimit(resource.RLIMIT_AS), "core": resource.getrlimit(resource.RLIMIT_CORE)}
    answer.write(json.dumps({**limits, "echo": request["echo"]}).encode() + b"\\n")
elif request["do"] == "hang":  # a grandchild in its group, then silence
    sleeper = subprocess.Popen(["sleep", "600"])
    answer.write(b"%d\\n" % sleeper.pid)
    time.sleep(600)
elif request["do"] == "spin":  # a core looping on a state, the GIL held between its steps
    answer.write(b"%d\\n" % os.getpid())
    while True:
        pass
elif request["do"] == "fail":
    print("first words\\nlast words", file=sys.stderr)
    sys.exit(5)
elif request["do"] == "chatty":  # what a core prints: megabytes, a forged answer, bytes that are not UTF-8
    for fd in (1, 2):
        os.write(fd, b"noise\\n" * (1 << 18) + b'{"forged": true}\\n')
    answer.write(b"real\\n")
    os.write(1, b"last \\xff words\\n")
"""


@pytest.fixture
def child_module(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A module the child runs, on the child's path."""
    (tmp_path / f"{MODULE}.py").write_text(CHILD)
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))
    return tmp_path


def test_the_child_reads_its_request_and_runs_under_the_cap_with_no_core_file(child_module: Path) -> None:
    with Child(MODULE, {"do": "limits", "echo": "hello"}, memory=1 << 30) as child:
        (line,) = list(child.lines(first=120))
        end = child.end()
    answer = json.loads(line)
    assert answer == {"as": [1 << 30, 1 << 30], "core": [0, 0], "echo": "hello"}
    assert (end.status, end.hung, end.signal) == (0, False, None)


def test_the_cap_never_exceeds_the_users_own_limit(child_module: Path) -> None:
    """Under ``ulimit -v`` of 1 GiB, a cap of 3 GiB becomes 1 GiB: raising a hard limit would fail."""
    code = f"""
        import resource
        resource.setrlimit(resource.RLIMIT_AS, (2**30, 2**30))
        from retrokit.host.child import Child
        with Child({MODULE!r}, {{"do": "limits", "echo": ""}}, memory=3 * 2**30) as child:
            print(b"".join(child.lines(first=120)).decode())
            print("status", child.end().status)
    """
    done = run_child(code, env={"PYTHONPATH": str(child_module)}, timeout=180)
    assert done.returncode == 0, done.describe()
    answer, status = done.stdout.splitlines()
    assert json.loads(answer)["as"] == [2**30, 2**30] and status == "status 0", done.describe()


def _gone(pid: int) -> bool:
    """Whether ``pid`` is dead: no such process, or a zombie nobody reaped yet."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] in "ZX"
    except (FileNotFoundError, ProcessLookupError):
        return True


def _wait_gone(pid: int) -> None:
    waited = time.monotonic()
    while not _gone(pid) and time.monotonic() - waited < 60:
        time.sleep(0.1)  # polling a condition (the kill is asynchronous), not timing it
    assert _gone(pid), f"the grandchild {pid} outlived its group's kill"


def test_a_silent_child_is_killed_past_its_deadline_with_its_whole_group(child_module: Path) -> None:
    with Child(MODULE, {"do": "hang"}, memory=1 << 30) as child:
        lines = list(child.lines(first=120, each=1))  # it prints one line, then nothing
        end = child.end()
    (grandchild,) = [int(line) for line in lines]
    assert end.hung and end.signal is None  # a deadline missed, not a crash
    _wait_gone(grandchild)


def test_a_failing_child_gives_its_status_and_last_words(child_module: Path) -> None:
    with Child(MODULE, {"do": "fail"}, memory=1 << 30) as child:
        assert list(child.lines(first=120)) == []
        end = child.end()
    assert (end.status, end.hung, end.last_words) == (5, False, "last words")


def test_only_the_answer_channel_answers_and_the_log_is_a_bounded_tail(child_module: Path) -> None:
    """A core's stdout and stderr (megabytes, a forged answer line, a byte that is not UTF-8) are its log, not its answer."""
    with Child(MODULE, {"do": "chatty"}, memory=1 << 30) as child:
        lines = list(child.lines(first=120))
        end = child.end()
        kept = len(child._tail)
    assert lines == [b"real"]
    assert (end.status, end.hung, end.last_words) == (0, False, "last \ufffd words")
    assert kept <= 1 << 16  # of the 3 MB it printed


def test_a_child_that_cannot_start_is_one_error_line(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "executable", str(tmp_path / "no-python"))
    with pytest.raises(ChildStartError) as info:
        Child(MODULE, {}, memory=1 << 30)
    message = str(info.value)
    assert "\n" not in message and "could not start: No such file or directory" in message, message
    assert info.value.reason == "No such file or directory"


def test_leaving_the_block_early_kills_the_child(child_module: Path) -> None:
    with pytest.raises(KeyboardInterrupt), Child(MODULE, {"do": "hang"}, memory=1 << 30) as child:
        grandchild = int(next(iter(child.lines(first=120))))
        raise KeyboardInterrupt  # Ctrl-C while the child runs
    assert child._proc.returncode is not None  # killed and reaped on the way out
    _wait_gone(grandchild)


def test_the_users_limits_here_are_untouched() -> None:
    """The caps are set on the child alone (prlimit on its pid), never on this process."""
    before = resource.getrlimit(resource.RLIMIT_AS), resource.getrlimit(resource.RLIMIT_CORE)
    with Child("json.tool", {}, memory=1 << 28) as child:  # any module that reads stdin and ends
        list(child.lines(first=120))
        child.end()
    assert (resource.getrlimit(resource.RLIMIT_AS), resource.getrlimit(resource.RLIMIT_CORE)) == before


def test_a_child_whose_answers_were_not_all_read_still_ends(child_module: Path) -> None:
    """end() reads the child's log while it waits: a caller that stopped reading answers early cannot leave the
    child blocked on a full log pipe."""
    import threading

    with Child(MODULE, {"do": "chatty"}, memory=1 << 30) as child:
        rescue = threading.Timer(120, child._kill)  # a blocked child fails this test, never hangs the suite
        rescue.start()
        end = child.end()  # not one answer read: the child writes megabytes of log first
        rescue.cancel()
    assert (end.status, end.hung, end.last_words) == (0, False, "last \ufffd words")


def test_a_child_ends_when_its_parent_is_killed(child_module: Path) -> None:
    """A parent killed while its child spins (SIGKILL: no ``with`` block ends it) leaves no child spinning on.

    The child leads a session of its own, so the kill reaches only the parent; the child's watch of its parent
    ends it within a second or so (it once spun for 76 minutes under a killed test).
    """
    parent = subprocess.Popen(
        [sys.executable, "-c", f"""
import sys
from retrokit.host.child import Child
with Child({MODULE!r}, {{"do": "spin"}}, memory=1 << 30) as child:
    print(next(child.lines(first=120)).decode().strip(), flush=True)
    import time; time.sleep(600)
"""], stdout=subprocess.PIPE, text=True)
    try:
        pid = int(parent.stdout.readline())
        assert alive(pid)
    finally:
        parent.kill()
        parent.wait()
    deadline = time.monotonic() + 60  # a generous bound for a loaded machine: the watch looks twice a second
    while alive(pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not alive(pid), f"the child {pid} spins on after its parent was killed"


def alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie its new parent has not reaped yet counts as ended)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return False
    return state not in ("Z", "X")
