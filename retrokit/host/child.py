"""The one way retrokit runs risky work in a child process: :class:`Child`.

Some work may take down the process that does it: loading a core whose bytes
nobody vouches for (:mod:`retrokit.host.corecheck`), running a state the core
may crash on (:mod:`retrokit.data.probe`). Such work runs in a child,
``python -m MODULE`` of the retrokit this process imported, and every such
child is run the same way, here:

- **Limits.** No core file, and an address space of at most ``memory``
  bytes, never above the limits this process runs under: raising a limit
  past the hard one fails (under ``ulimit -v``), and past the soft one would
  undo what the user asked for. They are set on the child (``prlimit``)
  before it is given its request, so nothing it is asked to load runs
  without them; no ``preexec_fn``, which may deadlock a child forked from a
  threaded process (the studio, a vector env).
- **Request.** One JSON object on the child's stdin, which it reads before it loads anything.
- **Answer.** Lines on a pipe of its own, on another file descriptor than
  stdout and stderr (:func:`answer_channel`), read with deadlines
  (:meth:`Child.lines`); past one, its whole process group is killed (it
  leads a session of its own). Leaving the ``with`` block early (an error,
  Ctrl-C) kills it too. What a core prints (a state's bytes may be in it:
  mednafen names a state's unknown variables on stdout) never reaches the
  answer, so no file a child loads can write its verdict.
- **Log.** Its stdout and stderr share another pipe, read as bytes while it
  runs; only their last :data:`_LOG_TAIL` bytes are kept, so a chatty core
  can neither fill a pipe nor this process's memory, and output never
  counts as an answer for a deadline. Their last line says why it failed,
  with undecodable bytes replaced.
- **Start.** A child that cannot start (no memory, no processes left) is one
  :class:`~retrokit.errors.ChildStartError` line, never a raw ``OSError``.
"""

from __future__ import annotations

import contextlib
import json
import os
import resource
import selectors
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO, Self

from retrokit.errors import ChildStartError

_LOG_TAIL = 1 << 16  # the bytes of a child's log kept for its last words
ANSWER_FD = "answer_fd"
#: The request's key naming the process that started the child (:func:`read_request` watches it).
PARENT = "parent_pid"
#: Seconds between two looks of a child at whether its parent is still there.
PARENT_POLL_SECONDS = 0.5
"""The request's key naming the file descriptor the child answers on (:func:`answer_channel`)."""


def read_request() -> dict[str, Any]:
    """In a child: its request, from stdin; and from then on, the child's end as soon as its parent is gone.

    A child leads a session of its own (so that its parent can kill its whole
    group past a deadline), so nothing ends it when the parent itself is
    killed (SIGKILL, the OOM killer, a test's timeout): a core looping on a
    state would spin on for good, reparented (one did, for 76 minutes, under a
    killed test). A thread looks every :data:`PARENT_POLL_SECONDS` and ends
    the process once its parent is another; it runs while frames do, as the
    native host lets go of the GIL for them. Not ``PR_SET_PDEATHSIG``: that
    fires when the *thread* that started the child ends, and the studio starts
    probes from worker threads that come and go.
    """
    request = json.load(sys.stdin)
    parent = request.get(PARENT)
    if not isinstance(parent, int):  # asked by a retrokit of before the watch, still running across an upgrade
        return request

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(PARENT_POLL_SECONDS)
        os._exit(1)  # nobody is left to read what it would say

    if os.getppid() != parent:  # gone before the watch began
        os._exit(1)
    threading.Thread(target=watch, name="parent watch", daemon=True).start()
    return request


def answer_channel(request: Mapping[str, Any]) -> BinaryIO:
    """In a child: the pipe its parent reads answers from, named by the request; not inherited by its own children.

    Write whole lines (``json.dumps(...) + "\\n"``, encoded) to it; it is unbuffered.
    """
    fd = int(request[ANSWER_FD])
    os.set_inheritable(fd, False)
    return open(fd, "wb", buffering=0)  # the child's one channel, open until it exits


def lowered(kind: int, cap: int) -> tuple[int, int]:
    """The limits ``kind`` may take to stay at or under ``cap``: never above the limits the user set already.

    Raising a limit above the hard one fails (under ``ulimit -v``), and above
    the soft one would undo what the user asked for.
    """
    soft, hard = resource.getrlimit(kind)
    for limit in (soft, hard):
        if limit != resource.RLIM_INFINITY:
            cap = min(cap, limit)
    return cap, cap


def child_env() -> dict[str, str]:
    """This process's environment, with the folder retrokit was imported from first on the path.

    The child does no linear algebra: one BLAS thread (unless the user chose
    otherwise) keeps numpy's thread stacks, one per CPU, out of its memory cap.
    """
    root = str(Path(__file__).resolve().parents[2])
    path = os.environ.get("PYTHONPATH")
    threads = {name: "1" for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS") if name not in os.environ}
    return {**os.environ, **threads, "PYTHONPATH": root + (os.pathsep + path if path else "")}


def signal_name(number: int) -> str:
    """``SIGSEGV`` for 11; ``signal 40`` for a signal without a name (a real-time one)."""
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


@dataclass(frozen=True)
class ChildEnd:
    """How a child ended.

    Attributes:
        status: Its exit status; negative when a signal killed it.
        hung: It missed a deadline of :meth:`Child.lines`, and was killed for it.
        last_words: The last line of its log (``"no message"`` when it wrote none).
    """

    status: int
    hung: bool
    last_words: str

    @property
    def signal(self) -> str | None:
        """The signal that killed it, by name, unless it exited (or was killed for a deadline)."""
        return signal_name(-self.status) if self.status < 0 and not self.hung else None

    @property
    def lasting(self) -> bool:
        """Whether how it ended speaks of what it ran, so a verdict drawn from it may be kept.

        A child that missed its deadline may only have been starved of a CPU on a
        loaded machine (two cores shared by many processes), not stuck: such a
        verdict holds for this moment, and the next run probes again.
        """
        return not self.hung


class Child:
    """``python -m MODULE`` in a child process, with limits, given ``request``; use it in a ``with`` block.

    Args:
        module: The module the child runs (it reads ``request`` as JSON from its stdin).
        request: What it is asked to do.
        memory: Its address-space cap in bytes (lowered to this process's own limits).

    Raises:
        ChildStartError: The child could not start, or its limits could not be set.
    """

    def __init__(self, module: str, request: Mapping[str, Any], *, memory: int) -> None:
        self.module = module
        self.hung = False
        self._tail = b""
        try:
            self._answers, answer_end = os.pipe()
        except OSError as exc:
            raise self._start_failed(exc) from None
        try:
            self._proc = subprocess.Popen(
                [sys.executable, "-P", "-m", module], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT, bufsize=0, env=child_env(), start_new_session=True, pass_fds=(answer_end,),
            )  # fmt: skip
        except (OSError, subprocess.SubprocessError) as exc:
            os.close(self._answers)
            raise self._start_failed(exc) from None
        finally:
            os.close(answer_end)  # the child's end: its exit closes the pipe
        request = {**request, ANSWER_FD: answer_end, PARENT: os.getpid()}
        try:
            self._limit(memory)
        except OSError as exc:
            self.close()
            raise self._start_failed(exc) from None
        try:
            self._proc.stdin.write(json.dumps(request).encode())  # type: ignore[union-attr]
            self._proc.stdin.close()  # type: ignore[union-attr]
        except BrokenPipeError:  # it died at once; its status says why
            pass

    def _limit(self, memory: int) -> None:
        """No core file from a crash, and the memory cap: on the child, before it reads its request."""
        pid = self._proc.pid
        try:
            resource.prlimit(pid, resource.RLIMIT_CORE, (0, 0))
            resource.prlimit(pid, resource.RLIMIT_AS, lowered(resource.RLIMIT_AS, memory))
        except ProcessLookupError:  # it is gone already: it loaded nothing, and its status says why
            pass

    def _start_failed(self, exc: BaseException) -> ChildStartError:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        error = ChildStartError(
            f"Expected to start a child process (python -m {self.module}) to try a core or a state in; it could not start: "
            f"{reason}. Free some memory or processes (or raise ulimit -v / -u), then run the command again."
        )
        error.reason = reason
        return error

    def lines(self, *, first: float, each: float | None = None) -> Iterator[bytes]:
        """The lines the child answers (:func:`answer_channel`), as they come, until it ends; past a deadline it is
        killed (:attr:`hung`). Its stdout and stderr are read meanwhile, into its log.

        Args:
            first: Seconds it may take to answer anything, its start included
                (with ``each`` ``None``: to finish).
            each: Seconds it may then take between two answers.
        """
        # Raw reads, split here: a buffered reader could hold a line that select() then waits for.
        output = self._proc.stdout.fileno()  # type: ignore[union-attr]
        pending = b""
        deadline = time.monotonic() + first
        with selectors.DefaultSelector() as selector:
            selector.register(self._answers, selectors.EVENT_READ)
            selector.register(output, selectors.EVENT_READ)
            while selector.get_map():  # until both close: it must not block on a full log pipe as it exits
                ready = selector.select(timeout=max(0.0, deadline - time.monotonic()))
                if not ready:
                    self._expire()
                    return
                for key, _ in ready:
                    if key.fd == output:
                        if not self._keep_output(output):
                            selector.unregister(output)
                        continue
                    chunk = os.read(self._answers, 1 << 16)
                    if not chunk:
                        selector.unregister(self._answers)
                        continue
                    if each is not None:
                        deadline = time.monotonic() + each
                    *done, pending = (pending + chunk).split(b"\n")
                    yield from done
        try:  # its pipes closed: it must end within the same deadline
            self._proc.wait(timeout=max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            self._expire()

    def _keep_output(self, fd: int) -> bool:
        """Read what the child printed into the log's bounded tail; return whether more may come."""
        chunk = os.read(fd, 1 << 16)
        self._tail = (self._tail + chunk)[-_LOG_TAIL:]
        return bool(chunk)

    def _drain(self, fd: int) -> bool:
        """Read all the (non-blocking) log holds now; return whether more may come."""
        try:
            while self._keep_output(fd):
                pass
        except BlockingIOError:
            return True
        return False

    def end(self) -> ChildEnd:
        """Wait for the child to end; return how it did."""
        output = self._proc.stdout.fileno()  # type: ignore[union-attr]
        os.set_blocking(output, False)
        with selectors.DefaultSelector() as selector:  # its log is read while it ends: a full pipe would block it
            selector.register(output, selectors.EVENT_READ)
            while self._proc.poll() is None:
                if selector.select(timeout=0.1) and not self._drain(output):
                    break
        status = self._proc.wait()
        with contextlib.suppress(ProcessLookupError, PermissionError):  # what it left running holds its log open
            os.killpg(self._proc.pid, signal.SIGKILL)
        self._drain(output)
        text = self._tail.decode("utf-8", errors="replace")
        return ChildEnd(status, self.hung, (text.strip().splitlines() or ["no message"])[-1])

    def _expire(self) -> None:
        self.hung = True
        self._kill()

    def _kill(self) -> None:
        with contextlib.suppress(ProcessLookupError):  # its group: whatever it started goes with it
            os.killpg(self._proc.pid, signal.SIGKILL)

    def close(self) -> None:
        """Kill the child if it still runs, and wait for it: it never runs on alone."""
        if self._proc.poll() is None:
            self._kill()
            self._proc.wait()
        for stream in (self._proc.stdin, self._proc.stdout):
            if stream is not None:
                stream.close()
        if self._answers >= 0:
            os.close(self._answers)
            self._answers = -1

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
