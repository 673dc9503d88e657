"""The local backend: levels shared among processes on this machine.

With one worker the levels run in this process, one after the other. With N,
this process is one of the N: it starts N - 1 worker processes and plays
levels itself too, so no core waits for a process to start up. Each takes
the next level from a shared counter; the workers' messages come back on one
queue, which this process reads between its own episodes, then until every
level is done. A level's result depends only on its own seed, never on
which process played it.
"""

from __future__ import annotations

import multiprocessing
import queue
import signal
from collections.abc import Callable

from retrokit.benchmark.level import LevelTask, Message, run_level

POLL_SECONDS = 0.5


def run_local(tasks: list[LevelTask], handle: Callable[[Message], None], workers: int) -> None:
    """Run ``tasks`` on ``workers`` processes, this one included, passing each message to ``handle``."""
    if workers <= 1 or len(tasks) <= 1:
        for task in tasks:
            run_level(task, handle)
        return
    # spawn, not fork: the parent may hold threads (tqdm's, the emulator host's) that fork would copy half-way.
    context = multiprocessing.get_context("spawn")
    counter, messages = context.Value("i", 0), context.Queue()
    processes = [context.Process(target=_worker, args=(tasks, counter, messages), daemon=True)
                 for _ in range(min(workers, len(tasks)) - 1)]
    for process in processes:
        process.start()
    running: dict[int, str] = {}  # worker pid -> the level it plays
    remaining = {task.level.name for task in tasks}

    def take(message: Message) -> None:
        if message.kind == "start":
            running[message.data["pid"]] = message.level
            return
        if message.kind in ("done", "failed"):
            remaining.discard(message.level)
        handle(message)

    def drain() -> None:
        while True:
            try:
                take(messages.get_nowait())
            except queue.Empty:
                return

    def mine(message: Message) -> None:  # this process's own messages; the workers' are read between them
        take(message)
        drain()

    try:
        while (task := _next(tasks, counter)) is not None:
            run_level(task, mine)
        while remaining:
            try:
                take(messages.get(timeout=POLL_SECONDS))
            except queue.Empty:
                _check_workers(processes, running, remaining, handle)
    finally:
        for process in processes:
            if process.is_alive():
                process.terminate()
        for process in processes:
            process.join(timeout=5)
        messages.close()


def _next(tasks: list[LevelTask], counter) -> LevelTask | None:  # a shared multiprocessing Value
    """The next level nobody has taken, or ``None``."""
    with counter.get_lock():
        index = counter.value
        counter.value += 1
    return tasks[index] if index < len(tasks) else None


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


def _worker(tasks: list[LevelTask], counter, messages) -> None:  # a shared Value and a queue
    """A worker process: play levels until none is left."""
    import os

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle; it stops the workers
    while (task := _next(tasks, counter)) is not None:
        messages.put(Message("start", task.level.name, {"pid": os.getpid()}))
        run_level(task, messages.put)
