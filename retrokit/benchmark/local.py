"""The local backend: every level in a worker process of its own, at most N at a time.

The command's own process plays nothing: an agent that calls ``os._exit``,
raises ``SystemExit`` or crashes in native code takes down only its level's
worker, and the evaluation reports that level and keeps the others. Each
worker sends its messages down a pipe; this process waits on the pipes and
the workers' exits together, and feeds the
:class:`~retrokit.benchmark.watchdog.Watchdog`, which stops a stalled worker.
A worker dies with this process (a parent-death signal on Linux, and a thread
that watches the parent everywhere), so a killed evaluation leaves no worker
playing on. A level's result depends only on its own seed, never on which
process played it.

Workers are forked by multiprocessing's fork server, which imported what a
level needs once (:mod:`retrokit.benchmark.preload`): a worker starts in
milliseconds instead of the second a fresh interpreter takes to import
numpy, Gymnasium and retrokit. The server is a single-threaded process of
its own, so forking it copies no half-held lock (forking this process, which
may hold tqdm's and the host's threads, would). A worker takes this process's
environment variables as they are when its level starts, not the server's
(:func:`_work`). Where there is no fork server (Windows), workers are spawned.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait

from retrokit.benchmark.level import LevelDone, LevelFailed, LevelTask, Message, Started, run_level
from retrokit.benchmark.watchdog import Watchdog

POLL_SECONDS = 0.5
_PR_SET_PDEATHSIG = 1  # from <linux/prctl.h>
WORKER_NAME = "retrokit level "
"""How a worker process's name starts (then the level's name)."""
_GUARD = (
    "put the code that starts the evaluation under `if __name__ == \"__main__\":` (as multiprocessing asks): "
    "every level's worker imports the script that started the evaluation again, and this one starts an evaluation "
    "when imported."
)


@dataclass
class _Worker:
    task: LevelTask
    process: multiprocessing.process.BaseProcess
    pipe: Connection
    heard: bool = False  # the worker sent a message: it got as far as the level
    ended: bool = False  # the level sent LevelDone or LevelFailed


def run_local(tasks: list[LevelTask], handle: Callable[[Message], None], workers: int, watchdog: Watchdog) -> None:
    """Play each of ``tasks`` in a worker process, ``workers`` at a time, passing each message to ``handle``."""
    context = _context()
    pending = list(reversed(tasks))
    running: dict[Connection, _Worker] = {}
    try:
        while pending or running:
            while pending and len(running) < workers:
                task = pending.pop()
                reader, writer = context.Pipe(duplex=False)
                process = context.Process(target=_work, args=(task, writer, dict(os.environ)), daemon=True,
                                          name=f"{WORKER_NAME}{task.level.name}")
                _start(process, context)
                writer.close()  # the worker holds the only writer: its exit ends the pipe
                watchdog.start(task.level.name)
                running[reader] = _Worker(task, process, reader)
            wait([*running, *(worker.process.sentinel for worker in running.values())], timeout=POLL_SECONDS)
            for pipe, worker in list(running.items()):
                if _read(worker, handle, watchdog):
                    continue
                del running[pipe]
                worker.process.join()
                if not worker.ended:
                    handle(_died(worker, watchdog))
                watchdog.stop(worker.task.level.name)
            for level in watchdog.stalled():
                pipe, worker = next((p, w) for p, w in running.items() if w.task.level.name == level)
                worker.process.kill()
                worker.process.join()
                del running[pipe]
                pipe.close()
                handle(LevelFailed(level, watchdog.error(level), watchdog.timesteps(level)))
                watchdog.stop(level)
    finally:
        for worker in running.values():
            worker.process.kill()
        for worker in running.values():
            worker.process.join(timeout=10)
            worker.pipe.close()


def _context() -> multiprocessing.context.BaseContext:
    """The fork server's context, preloading what a level needs; spawn where there is none."""
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(["retrokit.benchmark.preload"])
    return context


def _start(process: multiprocessing.process.BaseProcess, context: multiprocessing.context.BaseContext) -> None:
    """Start a worker with Ctrl-C blocked: a terminal's SIGINT goes to the whole process group, and it is this
    process's to handle (it stops the workers); the mask is inherited, so not even the worker's start sees it.

    The fork server is started here too if it is not running yet, so it and every worker it forks inherit the
    mask (a server started with Ctrl-C open would fork workers that a Ctrl-C could interrupt before they
    ignore it).
    """
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        if context.get_start_method() == "forkserver":
            from multiprocessing import forkserver

            forkserver.ensure_running()
        with _main_file_only_if_it_exists():
            process.start()
    finally:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})  # a Ctrl-C meanwhile arrives now


@contextlib.contextmanager
def _main_file_only_if_it_exists() -> Iterator[None]:
    """Hide ``__main__.__file__`` while a worker starts when it names no file (``<stdin>``: ``python - < script``).

    multiprocessing asks each worker to run the file ``__main__`` came from again; for a script read from stdin
    that is ``<stdin>``, no file, and every worker died of FileNotFoundError before its level. Without a
    ``__file__`` the worker skips that step, as it does for ``python -c`` and a notebook (whose code it cannot
    run again either).
    """
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    by_name = getattr(getattr(main, "__spec__", None), "name", None)  # python -m: the worker imports the module
    if main is None or path is None or by_name is not None or os.path.isfile(path):
        yield
        return
    del main.__file__
    try:
        yield
    finally:
        main.__file__ = path


def _read(worker: _Worker, handle: Callable[[Message], None], watchdog: Watchdog) -> bool:
    """Pass on every message the worker has sent; ``False`` once its pipe is closed (the worker ended)."""
    try:
        while worker.pipe.poll():
            message = worker.pipe.recv()
            worker.heard = True
            watchdog.see(message)
            if isinstance(message, LevelDone | LevelFailed):
                worker.ended = True
                watchdog.stop(message.level)  # its process may take a moment to exit: that is no stall
            if not isinstance(message, Started):
                handle(message)
    except (EOFError, OSError):
        worker.pipe.close()
        return False
    return True


def _died(worker: _Worker, watchdog: Watchdog) -> LevelFailed:
    """The failure of a level whose worker ended without finishing it."""
    level, code = worker.task.level.name, worker.process.exitcode or 0
    how = f"was killed by signal {signal.Signals(-code).name}" if code < 0 else f"exited with status {code}"
    if not worker.heard:
        return LevelFailed(level, (
            f"The worker for level {level} {how} before it started the level (its error, if it printed one, is "
            f"above). If a script of yours started the evaluation, {_GUARD}"), 0)
    step = watchdog.timesteps(level)
    return LevelFailed(level, (
        f"The worker playing level {level} {how} (its last report: step {step:,}) before the level was finished: "
        "the agent ended its process (os._exit) or crashed in native code."), step)


def refuse_inside_a_worker() -> None:
    """End this process, saying why, if it is an evaluation's worker about to start an evaluation of its own.

    multiprocessing imports the script that started the evaluation again in each worker (as ``__mp_main__``)
    before the worker plays its level. A script that starts an evaluation at its top level would start one more
    in every worker, and run whatever comes after it there. The worker ends instead (status 2, one line on
    stderr), and the evaluation reports the level as failed with the same advice.
    """
    if multiprocessing.current_process().name.startswith(WORKER_NAME):
        sys.stderr.write(f"retrokit: error: Expected no evaluation to start inside an evaluation's worker: {_GUARD}\n")
        sys.stderr.flush()
        os._exit(2)  # not an exception: the script's own handlers (or retrokit.cli.main's) would carry on


def _work(task: LevelTask, pipe: Connection, environment: dict[str, str]) -> None:
    """A worker process: play one level, sending every message down ``pipe``.

    ``environment`` is the evaluation's environment variables when the level started: a forked worker has the
    fork server's, which are the evaluation's as they were when the server started (RETROKIT_GAMES,
    RETROKIT_DATA and the like may have changed since).
    """
    _die_with_parent()
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # also if the agent unblocks it: Ctrl-C is the parent's
    os.environ.clear()
    os.environ.update(environment)
    run_level(task, pipe.send)
    pipe.close()
    # Exit now: a thread the agent left running must not keep the process (and the evaluation) waiting.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)


def _die_with_parent() -> None:
    """End this process as soon as the evaluation's process is gone, whatever the agent is doing.

    The parent-death signal fires when this process's parent ends: the evaluation where workers are spawned,
    the fork server where they are forked (which ends when the evaluation does). The thread watches the
    evaluation itself: ``parent_process()`` is it for both start methods (multiprocessing hands the worker a
    pipe end that the evaluation holds open while it lives).
    """
    if sys.platform.startswith("linux"):
        import ctypes

        try:
            ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        except (OSError, AttributeError):
            pass  # the watching thread below still ends it
    evaluation = multiprocessing.parent_process()
    if evaluation is None or not evaluation.is_alive():  # it died before the signal was set up
        os._exit(1)

    def watch() -> None:
        evaluation.join()
        os._exit(1)

    threading.Thread(target=watch, name="retrokit parent watch", daemon=True).start()
