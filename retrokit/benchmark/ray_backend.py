"""The Ray backend: one Ray task per level, on a local Ray or an existing cluster.

Each task runs :func:`~retrokit.benchmark.level.run_level` and puts its
messages on a Ray queue as they come, so episodes stream back while levels
play. Ray is the optional extra ``retrokit-rl[ray]``; every node of a cluster
needs retrokit (and the ROMs of the benchmark's games) installed.
"""

from __future__ import annotations

import logging
import os
import queue
from collections.abc import Callable

from retrokit.benchmark.level import LevelTask, Message, run_level
from retrokit.errors import BackendUnavailableError, install_extra

POLL_SECONDS = 0.2


def _play(task: LevelTask, messages) -> int:  # a ray.util.queue.Queue
    """A Ray task: play one level, streaming its messages."""
    run_level(task, messages.put)
    return 0


def run_ray(tasks: list[LevelTask], handle: Callable[[Message], None], workers: int, address: str | None) -> None:
    """Run ``tasks`` as Ray tasks, passing each message to ``handle``.

    Args:
        tasks: One per level.
        handle: Called with every message, in this process.
        workers: CPUs of the local Ray started when ``address`` is ``None``.
        address: An existing cluster's address (``ray://host:10001``, ``host:6379`` or ``auto``).
    """
    try:
        import ray
        from ray.util.queue import Empty, Queue
    except ImportError:
        raise BackendUnavailableError(
            f"Expected Ray for --backend ray, but it is not installed; run `{install_extra('ray')}`."
        ) from None
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")  # no telemetry from a benchmark run
    started = not ray.is_initialized()
    if started:
        try:
            if address:
                ray.init(address=address, logging_level=logging.WARNING, log_to_driver=False)
            else:
                ray.init(num_cpus=max(1, workers), include_dashboard=False, logging_level=logging.WARNING,
                         log_to_driver=False)
        except (ConnectionError, RuntimeError, ValueError) as exc:
            raise BackendUnavailableError(
                f"Expected a Ray cluster at {address or 'a new local Ray'}, but it could not start or connect: {exc}."
            ) from None
    try:
        messages = Queue()
        play = ray.remote(num_cpus=1, max_retries=0)(_play)
        pending = {play.remote(task, messages): task.level.name for task in tasks}
        while pending:
            _drain(messages, handle, Empty, block=True)
            ready, _ = ray.wait(list(pending), num_returns=len(pending), timeout=0)
            for ref in ready:
                level = pending.pop(ref)
                try:
                    ray.get(ref)
                except Exception as exc:  # noqa: BLE001 - a task lost to Ray (node died, worker killed)
                    _drain(messages, handle, Empty, block=False)
                    handle(Message("failed", level, {"error": f"The Ray task of level {level} failed: {exc}",
                                                     "timesteps": 0}))
        _drain(messages, handle, Empty, block=False)
    finally:
        if started:
            ray.shutdown()


def _drain(messages, handle, empty_error, *, block: bool) -> None:
    """Pass on every message waiting in the Ray queue (waiting a moment for the first if ``block``)."""
    try:
        first = messages.get(block=block, timeout=POLL_SECONDS if block else None)
    except (empty_error, queue.Empty):
        return
    handle(first)
    while True:
        try:
            handle(messages.get_nowait())
        except (empty_error, queue.Empty):
            return
