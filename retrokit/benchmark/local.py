"""The local backend: levels shared among worker processes on this machine.

With one worker the levels run in this process, one after the other. With
more, each worker process takes the next level from a queue, so the levels
spread over the machine's cores; every message comes back on one queue. A
level's result depends only on its own seed, never on which worker ran it.
"""

from __future__ import annotations

import multiprocessing
import queue
import signal
from collections.abc import Callable

from retrokit.benchmark.level import LevelTask, Message, run_level

POLL_SECONDS = 0.5


def run_local(tasks: list[LevelTask], handle: Callable[[Message], None], workers: int) -> None:
    """Run ``tasks`` on ``workers`` processes (or here, for one), passing each message to ``handle``."""
    if workers <= 1 or len(tasks) <= 1:
        for task in tasks:
            run_level(task, handle)
        return
    # spawn, not fork: the parent may hold threads (tqdm's, the emulator host's) that fork would copy half-way.
    context = multiprocessing.get_context("spawn")
    todo, messages = context.Queue(), context.Queue()
    for task in tasks:
        todo.put(task)
    count = min(workers, len(tasks))
    for _ in range(count):
        todo.put(None)
    processes = [context.Process(target=_worker, args=(todo, messages), daemon=True) for _ in range(count)]
    for process in processes:
        process.start()
    running: dict[int, str] = {}  # worker pid -> the level it plays
    remaining = {task.level.name for task in tasks}
    try:
        while remaining:
            try:
                message = messages.get(timeout=POLL_SECONDS)
            except queue.Empty:
                _check_workers(processes, running, remaining, handle)
                continue
            if message.kind == "start":
                running[message.data["pid"]] = message.level
                continue
            if message.kind in ("done", "failed"):
                remaining.discard(message.level)
            handle(message)
    finally:
        for process in processes:
            if process.is_alive():
                process.terminate()
        for process in processes:
            process.join(timeout=5)
        todo.close()
        messages.close()


def _check_workers(processes, running: dict[int, str], remaining: set[str], handle) -> None:
    """Fail the level of any worker that died (a crash in native code, the OOM killer)."""
    for process in processes:
        if process.exitcode not in (None, 0) and running.get(process.pid) in remaining:
            level = running.pop(process.pid)
            remaining.discard(level)
            how = f"signal {-process.exitcode}" if process.exitcode < 0 else f"exit code {process.exitcode}"
            handle(Message("failed", level, {"error": f"The worker playing level {level} died ({how}).", "timesteps": 0}))
    if not any(process.is_alive() for process in processes) and remaining:
        for level in sorted(remaining):
            handle(Message("failed", level, {"error": f"No worker is left to play level {level}.", "timesteps": 0}))
        remaining.clear()


def _worker(todo, messages) -> None:  # two multiprocessing queues
    """A worker process: play levels from ``todo`` until its end mark."""
    import os

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle; it stops the workers
    while (task := todo.get()) is not None:
        messages.put(Message("start", task.level.name, {"pid": os.getpid()}))
        run_level(task, messages.put)
