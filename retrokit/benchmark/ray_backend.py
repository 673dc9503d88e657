"""The Ray backend: one Ray task per level, on a local Ray or an existing cluster.

Each task runs :func:`~retrokit.benchmark.level.run_level` and puts its
messages on a Ray queue as they come, so episodes stream back while levels
play; the :class:`~retrokit.benchmark.watchdog.Watchdog` cancels a stalled
task. A level whose node is lost (``NodeDiedError``) starts again from its
beginning on the nodes left, up to :data:`NODE_RETRIES` times: its episodes so
far are dropped, as ``--resume`` drops an unfinished level's, so the result is
the uninterrupted one. The queue lives on this process's node, which the run
cannot lose anyway. Ray is the optional extra ``retrokit-rl[ray]``; every node of a cluster
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
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from retrokit.benchmark.level import LevelDone, LevelFailed, LevelRestarted, LevelTask, Message, Started, run_level
from retrokit.benchmark.watchdog import Watchdog
from retrokit.errors import BackendUnavailableError, install_extra

POLL_SECONDS = 0.2
#: How many times a level whose Ray node is lost starts again on the nodes left, before it fails.
NODE_RETRIES = 3
#: How long a cluster's address may take to accept a connection.
CONNECT_SECONDS = 10.0


def _play(task: LevelTask, attempt: int, messages) -> int:  # a ray.util.queue.Queue
    """A Ray task: play one level, streaming its messages tagged with the attempt (a lost one's are dropped)."""
    run_level(task, lambda message: messages.put((attempt, message)))
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
    with connected(address, workers) as ray:
        from ray.util.queue import Empty, Queue

        _play_all(ray, Queue, Empty, tasks, handle, watchdog)


@contextmanager
def connected(address: str | None, cpus: int) -> Iterator[Any]:
    """Ray, connected to the cluster at ``address`` (checked first), or to a new local Ray of ``cpus`` CPUs.

    Every use of Ray goes through here (``evaluate``'s levels, ``train``'s env runners): a Ray this process
    already joined is used as it is; one started here is shut down on leaving.

    Raises:
        BackendUnavailableError: Ray is not installed, or the address is malformed, unreachable, or no Ray.
    """
    if importlib.util.find_spec("ray") is not None and address:
        check_address(address)
    try:
        import ray
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
                # "local": a new Ray of this run's own, never the last cluster started on this machine, which
                # ray.init() without an address joins (/tmp/ray/ray_current_cluster, or $RAY_ADDRESS)
                ray.init(address="local", num_cpus=max(1, cpus), include_dashboard=False,
                         logging_level=logging.WARNING, log_to_driver=False)
        except (ConnectionError, RuntimeError, ValueError) as exc:
            raise BackendUnavailableError(
                f"Expected a Ray cluster at {address or 'a new local Ray'}, but it could not start or connect: {exc}."
            ) from None
    try:
        yield ray
    finally:
        if started:
            ray.shutdown()


def _play_all(ray, queue_type, empty_error, tasks: list[LevelTask], handle: Callable[[Message], None],
              watchdog: Watchdog) -> None:
    """Run ``tasks`` on the connected Ray, retrying a level whose node is lost (see :data:`NODE_RETRIES`)."""
    messages = queue_type(actor_options=on_this_node(ray))
    play = ray.remote(num_cpus=1, max_retries=0)(_play)
    pending: dict = {}  # a running task's ref -> its task
    attempts: dict[str, int] = {}  # level -> its attempt now playing (messages of earlier ones are stale)
    ended: set[str] = set()

    def submit(task: LevelTask) -> None:
        attempt = attempts.get(task.level.name, -1) + 1
        attempts[task.level.name] = attempt
        pending[play.remote(task, attempt, messages)] = task

    def take(tagged: tuple[int, Message]) -> None:
        attempt, message = tagged
        if attempts.get(message.level) != attempt or message.level in ended:
            return  # from the attempt of a lost node, or after its level ended
        watchdog.see(message)
        if isinstance(message, LevelDone | LevelFailed):
            ended.add(message.level)
            watchdog.stop(message.level)
        if not isinstance(message, Started):
            handle(message)

    for task in tasks:
        submit(task)
    while pending:
        _drain(messages, take, empty_error, block=True)
        ready, _ = ray.wait(list(pending), num_returns=len(pending), timeout=0)
        for ref in ready:
            _drain(messages, take, empty_error, block=False)
            task = pending.pop(ref)
            level = task.level.name
            watchdog.stop(level)
            try:
                ray.get(ref)
            except ray.exceptions.NodeDiedError as exc:
                if level in ended:
                    continue
                if attempts[level] < NODE_RETRIES:
                    handle(LevelRestarted(level, (
                        f"the Ray node playing level {level} was lost ({_first_line(exc)}); the level starts "
                        f"again from its beginning on the nodes left (retry {attempts[level] + 1} of {NODE_RETRIES})")))
                    submit(task)
                else:
                    ended.add(level)
                    handle(LevelFailed(level, (
                        f"The Ray nodes playing level {level} were lost {NODE_RETRIES + 1} times, the last: "
                        f"{_first_line(exc)}. Check the cluster's nodes, then add --resume."), 0))
                continue
            except Exception as exc:  # noqa: BLE001 - a task lost to Ray (its worker killed, out of memory)
                if level not in ended:
                    ended.add(level)
                    handle(LevelFailed(level, f"The Ray task of level {level} failed: {exc}", 0))
                continue
            if level not in ended:
                ended.add(level)
                handle(LevelFailed(level, f"The Ray task of level {level} ended before the level did.", 0))
        for level in watchdog.stalled():
            ref = next(r for r, task in pending.items() if task.level.name == level)
            ray.cancel(ref, force=True)
            del pending[ref]
            ended.add(level)
            handle(LevelFailed(level, watchdog.error(level), watchdog.timesteps(level)))
            watchdog.stop(level)


def on_this_node(ray) -> dict:
    """Ray options that keep an actor on this process's node: a message queue must outlive any other node."""
    from ray.util.scheduling_strategies import NodeAffinitySchedulingStrategy

    try:
        node = ray.get_runtime_context().get_node_id()
    except Exception:  # noqa: BLE001 - a Ray client may not know its node: then Ray places the queue
        return {"num_cpus": 0}
    return {"num_cpus": 0, "scheduling_strategy": NodeAffinitySchedulingStrategy(node, soft=False)}


def _first_line(exc: BaseException) -> str:
    return str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__


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
