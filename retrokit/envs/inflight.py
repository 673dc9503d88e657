"""Steps in flight: the bookkeeping of a vector env's asynchronous mode (``send`` / ``recv``).

``send`` hands some envs' actions to a pool of threads and returns at once;
each thread runs one env's whole step (its frames with the GIL released,
then its fields and scenario), and whichever thread is free takes the next
env waiting, so a descheduled thread holds up only the step it is running.
``recv`` returns the first steps that are done, as many as the vector env's
``batch_size`` (or all in flight, if fewer), in the order they finished,
of the steps the calling thread sent: two threads may drive their own envs
of one vector env, each receiving its own.

An env is in flight from its ``send`` to the ``recv`` that returns it; it
cannot be sent again in between, and every misuse (``recv`` with nothing in
flight, an env sent twice, an id out of range) is a one-line
:class:`~retrokit.errors.EnvError` or
:class:`~retrokit.errors.InvalidArgumentError`.
"""

from __future__ import annotations

import collections
import numbers
import queue
import threading
from collections import Counter
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
from gymnasium.vector import VectorEnv

from retrokit.errors import EnvError, InvalidArgumentError, shown

#: Runs one env's step: ``step(env_id, action)`` returns its 5-tuple.
StepOne = Callable[[int, Any], tuple]
#: A finished step: ``(env_id, result, None)``, or ``(env_id, None, error)`` for one that raised.
_Done = tuple[int, "tuple | None", "BaseException | None"]


class InFlight:
    """Envs whose steps were sent and not yet received, per thread that sent them.

    Each thread's ``recv`` returns the steps that thread sent, never another
    thread's: two threads may each drive their own envs of one vector env.
    A step that fails is raised by the ``recv`` that meets it; the other
    steps done meanwhile are kept, still in flight, and the next ``recv``
    returns them, so no env's step is lost with the one that failed.

    Args:
        num_envs: The vector env's envs; ids go from 0 to ``num_envs - 1``.
        threads: Threads that run the steps (the caller is not one of them: it is free while they run).
    """

    def __init__(self, num_envs: int, threads: int) -> None:
        self.num_envs, self.threads = num_envs, threads
        self._pool: ThreadPoolExecutor | None = None  # started at the first send: a sync-only user needs no threads
        self._lock = threading.Lock()  # guards the maps below: two threads may send and receive at once
        self._sender: dict[int, int] = {}  # env id in flight -> the thread that sent it
        self._done: dict[int, queue.SimpleQueue[_Done]] = {}  # per sending thread: its steps, as they finish
        self._kept: dict[int, collections.deque[_Done]] = {}  # per thread: steps done, kept back by a failed one

    @property
    def count(self) -> int:
        """How many envs are in flight (sent by any thread)."""
        return len(self._sender)

    def check_ids(self, env_ids: Any) -> list[int]:
        """The env ids a ``send`` names, checked: whole numbers in range, each once.

        Raises:
            InvalidArgumentError: An id is not a whole number, out of range, or named twice.
        """
        if env_ids is None:
            ids = list(range(self.num_envs))
        else:
            try:
                ids = list(np.asarray(env_ids).reshape(-1)) if not isinstance(env_ids, (str, bytes)) else None
            except (TypeError, ValueError):
                ids = None
            if ids is None or np.ndim(env_ids) > 1:
                raise InvalidArgumentError(
                    f"Expected env_ids to be a sequence of env indices (0 to {self.num_envs - 1}), or None for all; "
                    f"found {shown(env_ids)}."
                )
        if len(ids) > self.num_envs:  # some id is repeated: say so before looking at each
            raise InvalidArgumentError(
                f"Expected each env id at most once in a send, so at most {self.num_envs}; found {len(ids)} ids. "
                f"Send one action per env."
            )
        checked = []
        for value in ids:
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
                raise InvalidArgumentError(
                    f"Expected env ids to be whole numbers from 0 to {self.num_envs - 1}; found {shown(value)}."
                )
            if not 0 <= int(value) < self.num_envs:
                raise InvalidArgumentError(
                    f"Expected env ids from 0 to {self.num_envs - 1} (the vector env has {self.num_envs} envs); "
                    f"found {int(value)}."
                )
            checked.append(int(value))
        if len(set(checked)) != len(checked):
            twice = sorted(i for i, times in Counter(checked).items() if times > 1)
            raise InvalidArgumentError(
                f"Expected each env id at most once in a send; found {twice} more than once. Send one action per env."
            )
        if not checked:
            raise InvalidArgumentError("Expected at least one env id in a send; found none.")
        return checked

    def send(self, env_ids: Sequence[int], actions: Sequence[Any], step: StepOne) -> None:
        """Start the steps of ``env_ids`` (checked by :meth:`check_ids`), ``actions[k]`` for ``env_ids[k]``.

        ``step`` runs one env's step; it is given per call, not kept, so that
        the vector env (whose method it is) and this object make no cycle:
        closing the vector env frees its emulators without waiting for the
        garbage collector.

        Raises:
            EnvError: An env is still in flight (sent by this thread or another, and not received).
        """
        me = threading.get_ident()
        with self._lock:
            busy = sorted(i for i in env_ids if i in self._sender)
            if busy:
                raise EnvError(
                    f"Expected envs that are not in flight; envs {busy} were sent and not yet received. "
                    f"Call recv() until they come back before sending them again (from the thread that sent them)."
                )
            if self._pool is None:
                self._pool = ThreadPoolExecutor(max_workers=self.threads, thread_name_prefix="retrokit-async")
            done = self._done.setdefault(me, queue.SimpleQueue())
            self._kept.setdefault(me, collections.deque())
            for env_id in env_ids:
                self._sender[env_id] = me
        for env_id, action in zip(env_ids, actions):
            self._pool.submit(self._run, step, env_id, action, done)

    @staticmethod
    def _run(step: StepOne, env_id: int, action: Any, done: queue.SimpleQueue[_Done]) -> None:
        try:
            done.put((env_id, step(env_id, action), None))
        except BaseException as exc:  # noqa: BLE001 - any failure, raised by recv() in the caller's thread: never a hang
            done.put((env_id, None, exc))

    def recv(self, batch_size: int) -> list[tuple[int, tuple]]:
        """Wait for the first ``batch_size`` steps this thread sent to finish (all, if fewer); return ``(env_id, result)``s.

        Raises:
            EnvError: This thread has nothing in flight (no ``send`` since the last ``recv`` of every env it sent).
            RetrokitError: A step failed; its error is raised once the batch is in (the failed env is no
                longer in flight; the batch's other steps stay in flight, and the next ``recv`` returns them).
        """
        me = threading.get_ident()
        with self._lock:
            mine = sum(1 for sender in self._sender.values() if sender == me)
            others = len(self._sender) - mine
        if not mine:
            elsewhere = f" ({others} envs are in flight, sent by another thread: its recv() returns them)"
            raise EnvError(
                f"Expected a send() before recv(): no env is in flight from this thread{elsewhere if others else ''}. "
                "Call vec.send(actions) (or vec.send(actions, env_ids)) first, then recv()."
            )
        kept, done = self._kept[me], self._done[me]
        batch = [kept.popleft() if kept else done.get() for _ in range(min(batch_size, mine))]
        failed = [exc for _, _, exc in batch if exc is not None]
        good = [(env_id, result) for env_id, result, exc in batch if exc is None]
        if failed:
            with self._lock:
                for env_id, _, exc in batch:
                    if exc is not None:
                        del self._sender[env_id]
            kept.extendleft(reversed([entry for entry in batch if entry[2] is None]))
            if good:
                failed[0].add_note(f"The steps of envs {[e for e, _ in good]} are done; the next recv() returns them.")
            raise failed[0]
        with self._lock:
            for env_id, _ in good:
                del self._sender[env_id]
        return good  # type: ignore[return-value]

    def close(self) -> None:
        """Let the steps in flight finish, and stop the threads."""
        if self._pool is not None:
            self._pool.shutdown(wait=True)
            self._pool = None
        with self._lock:
            self._sender.clear()
            self._done.clear()
            self._kept.clear()


class _Rows(VectorEnv):
    """Only Gymnasium's info batching, for a batch of ``num_envs`` rows (a ``recv``'s, not the vector env's)."""

    def __init__(self, num_envs: int) -> None:  # no spaces: it batches infos, nothing else
        self.num_envs = num_envs

    def add(self, batched: dict[str, Any], info: dict[str, Any], row: int) -> dict[str, Any]:
        return self._add_info(batched, info, row)


def batch_infos(infos: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """The infos of a batch's rows, batched as Gymnasium's vector envs batch them (with ``_key`` masks)."""
    rows = _Rows(len(infos))
    batched: dict[str, Any] = {}
    for k, info in enumerate(infos):
        batched = rows.add(batched, info, k)
    return batched
