"""The Ray backend: one Ray task per level, on a local Ray or an existing cluster.

Each task runs :func:`~retrokit.benchmark.level.run_level` and puts its
messages on a Ray queue as they come, so episodes stream back while levels
play; the :class:`~retrokit.benchmark.watchdog.Watchdog` cancels a stalled
task. Ray is the optional extra ``retrokit-rl[ray]``; every node of a cluster
needs retrokit (and the ROMs of the benchmark's games) installed. A cluster's
address is tried with a plain connection first, because Ray itself retries an
unreachable address without end.
"""

from __future__ import annotations

import importlib.util
import logging
import os
import queue
import socket
from collections.abc import Callable

from retrokit.benchmark.level import LevelDone, LevelFailed, LevelTask, Message, Started, run_level
from retrokit.benchmark.watchdog import Watchdog
from retrokit.errors import BackendUnavailableError, install_extra

POLL_SECONDS = 0.2
#: How long a cluster's address may take to accept a connection.
CONNECT_SECONDS = 10.0


def _play(task: LevelTask, messages) -> int:  # a ray.util.queue.Queue
    """A Ray task: play one level, streaming its messages."""
    run_level(task, messages.put)
    return 0


def check_address(address: str, timeout: float = CONNECT_SECONDS) -> None:
    """Check that ``host:port`` (or ``ray://host:port``) accepts a connection; ``auto`` is left to Ray.

    Raises:
        BackendUnavailableError: The address is malformed, or nothing answers there within ``timeout`` seconds.
    """
    if address == "auto":
        return
    where = address.removeprefix("ray://")
    host, _, port = where.rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise BackendUnavailableError(
            f"Expected --ray-address as HOST:PORT, ray://HOST:PORT or auto, got {address!r}."
        )
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout):
            pass
    except OSError as exc:
        raise BackendUnavailableError(
            f"Expected a Ray cluster at {address}, but it could not be reached within {timeout:g} s "
            f"({exc.strerror or exc}); start it (`ray start --head`), or check the address."
        ) from None


def run_ray(tasks: list[LevelTask], handle: Callable[[Message], None], workers: int, address: str | None,
            watchdog: Watchdog) -> None:
    """Run ``tasks`` as Ray tasks, passing each message to ``handle``.

    Args:
        tasks: One per level.
        handle: Called with every message, in this process.
        workers: CPUs of the local Ray started when ``address`` is ``None``.
        address: An existing cluster's address (``ray://host:10001``, ``host:6379`` or ``auto``).
        watchdog: Stops a level whose agent stalls.
    """
    if importlib.util.find_spec("ray") is not None and address:
        check_address(address)
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
        ended: set[str] = set()

        def take(message: Message) -> None:
            watchdog.see(message)
            if isinstance(message, LevelDone | LevelFailed):
                ended.add(message.level)
                watchdog.stop(message.level)
            if not isinstance(message, Started) and message.level in pending.values():
                handle(message)

        while pending:
            _drain(messages, take, Empty, block=True)
            ready, _ = ray.wait(list(pending), num_returns=len(pending), timeout=0)
            for ref in ready:
                _drain(messages, take, Empty, block=False)
                level = pending.pop(ref)
                watchdog.stop(level)
                try:
                    ray.get(ref)
                except Exception as exc:  # noqa: BLE001 - a task lost to Ray (node died, worker killed)
                    if level not in ended:
                        handle(LevelFailed(level, f"The Ray task of level {level} failed: {exc}", 0))
                    continue
                if level not in ended:
                    handle(LevelFailed(level, f"The Ray task of level {level} ended before the level did.", 0))
            for level in watchdog.stalled():
                ref = next(r for r, name in pending.items() if name == level)
                ray.cancel(ref, force=True)
                del pending[ref]
                handle(LevelFailed(level, watchdog.error(level), watchdog.timesteps(level)))
                watchdog.stop(level)
    finally:
        if started:
            ray.shutdown()


def _drain(messages, take, empty_error, *, block: bool) -> None:
    """Pass on every message waiting in the Ray queue (waiting a moment for the first if ``block``)."""
    try:
        first = messages.get(block=block, timeout=POLL_SECONDS if block else None)
    except (empty_error, queue.Empty):
        return
    take(first)
    while True:
        try:
            take(messages.get_nowait())
        except (empty_error, queue.Empty):
            return
