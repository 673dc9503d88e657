"""A vector env that steps N emulators in one process, on threads.

For envs that offer a :class:`~retrokit.envs.stepper.Stepping` (retrokit's
own, unwrapped) a step is one native call: one native thread per CPU (the
calling one included) takes the emulators one at a time, runs their frames
and converts each screen straight into the batch, with the GIL released
throughout; Python only reads the fields and evaluates the scenarios around
it; envs that evaluate their scenario every frame take one such call per
frame (``envs/stepper.py``'s ``drive`` is the loop). A thread that the
machine deschedules holds up nobody: the emulators it has not taken are run
by whoever is free, and the caller waits only for those in progress
(``native/runner.c``). More envs than CPUs share the threads, so they never
crowd the machine. Other envs (wrapped ones, or plain ones with different
frame skips) are stepped on Python threads, which also overlap because the
host releases the GIL while frames run.

Besides ``step``, an envpool-style asynchronous mode (``send`` then
``recv``, see :mod:`retrokit.envs.inflight`) lets the caller work while the
envs step, and take the first envs done.

It follows ``gymnasium.vector.VectorEnv`` with next-step autoreset, like
Gymnasium's own vector envs: the step after an episode ends resets that env
and returns its first observation with reward 0; in the asynchronous mode,
the same holds per env: the ``send`` after the one whose step ended resets it.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import gymnasium
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space, concatenate, create_empty_array, iterate

from retrokit.envs.buffers import BufferPool, Pool, StepArrays
from retrokit.envs.inflight import InFlight, batch_infos
from retrokit.envs.memory import MIN_ENV_BYTES, build_envs, check_fits
from retrokit.envs.options import check_num_envs, check_seed
from retrokit.envs.pickling import PicklesAsArguments
from retrokit.envs.starts import per_env_states
from retrokit.envs.stepper import Stepping, StepResult, drive
from retrokit.errors import EnvError, InvalidArgumentError, MissingExtraError, shown
from retrokit.host.runner import Runner


class ThreadedVectorEnv(PicklesAsArguments, VectorEnv):
    """Steps several envs at once, one thread each.

    It pickles as its arguments (see :mod:`retrokit.envs.pickling`), so its
    ``env_fns`` must pickle for it to: functions of a module, or
    ``functools.partial`` of them (as :func:`make_vec` gives), not lambdas.
    Unpickled, it is a fresh vector env made by calling them again.

    Args:
        env_fns: Functions that each make one env; all must have the same spaces.
        threads: Threads that step them, the calling one included; ``None``
            uses one per CPU this process may run on (never more than envs).
            More envs than threads share them. The asynchronous mode runs
            steps on this many threads besides the caller's.
        batch_size: How many envs' steps :meth:`recv` returns at most (the
            first done); ``None``: all that were sent.
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        env_fns: Sequence[Callable[[], gymnasium.Env]],
        threads: int | None = None,
        batch_size: int | None = None,
    ) -> None:
        PicklesAsArguments.__init__(self, env_fns, threads, batch_size)
        if not env_fns:
            raise InvalidArgumentError("Expected at least one env function, got none.")
        if threads is not None and (not isinstance(threads, int) or isinstance(threads, bool) or threads < 1):
            raise InvalidArgumentError(f"Expected threads of 1 or more (or None for one per CPU), got {threads!r}.")
        if batch_size is not None and (
            not isinstance(batch_size, int) or isinstance(batch_size, bool) or not 1 <= batch_size <= len(env_fns)
        ):
            raise InvalidArgumentError(
                f"Expected batch_size from 1 to {len(env_fns)} (the number of envs), or None for all sent; "
                f"got {shown(batch_size)}."
            )
        self.batch_size = batch_size or len(env_fns)
        self.threads = min(len(env_fns), threads or available_cpus())
        self.envs = build_envs(env_fns)  # refuses a count that would not fit in memory, after two
        self.num_envs = len(self.envs)
        first = self.envs[0]
        for i, env in enumerate(self.envs[1:], 1):
            if env.observation_space != first.observation_space or env.action_space != first.action_space:
                raise InvalidArgumentError(
                    f"Expected every env to have env 0's spaces ({first.observation_space}, {first.action_space}); "
                    f"env {i} has ({env.observation_space}, {env.action_space}). Use the same game and options."
                )
        self.metadata = {**first.metadata, "autoreset_mode": AutoresetMode.NEXT_STEP}
        self.render_mode = first.render_mode
        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._observations = create_empty_array(self.single_observation_space, self.num_envs)
        space = self.observation_space
        self._batches = BufferPool(space.shape, space.dtype) if isinstance(space, gymnasium.spaces.Box) else None
        self._direct_screens = False
        self._step_arrays: Pool[StepArrays] | None = None
        self._autoreset = [False] * self.num_envs
        # The calling thread steps envs too; the pool's threads step the rest.
        self._pool = ThreadPoolExecutor(max_workers=max(self.threads - 1, 1), thread_name_prefix="retrokit-env")
        self._runner = self._native_runner()
        self._in_flight = InFlight(self.num_envs, self.threads)

    @property
    def native(self) -> bool:
        """Whether a step runs every env's frames in one native call (each env offers a ``stepping`` of one kind)."""
        return self._runner is not None

    def _native_runner(self) -> Runner | None:
        """A native runner when every env offers a stepping of the same kind, so they can share one."""
        # A wrapper has no `stepping` (Gymnasium's wrappers forward no attributes): its step is its own.
        steppings: list[Stepping | None] = [getattr(env, "stepping", None) for env in self.envs]
        if not all(isinstance(s, Stepping) for s in steppings) or len({s.kind for s in steppings}) != 1:
            return None
        self._steppings: list[Stepping] = steppings  # type: ignore[assignment]
        self._steppers = [s.stepper for s in self._steppings]
        # Each env's buttons become a row of one array the runner reads.
        self._actions = np.zeros((self.num_envs, steppings[0].kind[1]), dtype=np.uint16)
        for i, stepper in enumerate(self._steppers):
            stepper.use_masks(self._actions[i])
        self._direct_screens = all(s.direct_screen for s in self._steppings) and self._batches is not None
        infos = [s.info for s in self._steppings]
        names = {info[0] for info in infos if info is not None}
        if len(names) == 1 and all(info is not None for info in infos):
            keys = names.pop()
            num_envs = self.num_envs  # not self: a closure over self would keep the envs alive until GC
            self._step_arrays = Pool(lambda: StepArrays(num_envs, keys))
            self._field_values = [info[1] for info in infos]  # type: ignore[index]
        return Runner([s.emulator for s in self._steppings], self.threads - 1)

    def _each(self, job: Callable[[int], Any]) -> list[Any]:
        """Run ``job(i)`` for every env: the pool takes all but every ``threads``-th, which this thread runs."""
        if self.threads == 1:
            return [job(i) for i in range(self.num_envs)]
        mine = range(0, self.num_envs, self.threads)
        futures = {i: self._pool.submit(job, i) for i in range(self.num_envs) if i % self.threads}
        done = {i: job(i) for i in mine}
        return [done[i] if i in done else futures[i].result() for i in range(self.num_envs)]

    def reset(self, *, seed: int | Sequence[int | None] | None = None, options: dict[str, Any] | None = None):
        if isinstance(seed, (Sequence, np.ndarray)) and not isinstance(seed, str):
            seeds = [check_seed(s) for s in seed]  # one per env, as Gymnasium's vector envs take them
            if len(seeds) != self.num_envs:
                raise InvalidArgumentError(
                    f"Expected {self.num_envs} seeds (one per env), got {len(seeds)}; pass one int, or a list of "
                    f"{self.num_envs}."
                )
        else:
            first = check_seed(seed)
            seeds = [None if first is None else first + i for i in range(self.num_envs)]
        self._check_idle("reset")
        results = self._each(lambda i: self.envs[i].reset(seed=seeds[i], options=options))
        infos: dict[str, Any] = {}
        for i, (_, info) in enumerate(results):
            infos = self._add_info(infos, info, i)
        self._autoreset = [False] * self.num_envs
        return self._batch([r[0] for r in results]), infos

    def _batch(self, observations: list[Any]) -> Any:
        """Stack the envs' observations into an array the caller may keep."""
        if self._batches is None:
            self._observations = concatenate(self.single_observation_space, observations, self._observations)
            return self._observations.copy()
        return concatenate(self.single_observation_space, observations, self._batches.take())

    def _check_idle(self, call: str) -> None:
        """Refuse a synchronous call while envs are in flight: they are the threads' until received.

        Raises:
            EnvError: Some env was sent and not received.
        """
        if self._in_flight.count:
            raise EnvError(
                f"Expected no env in flight at {call}(); some were sent and not received. Call recv() until "
                f"every env sent came back, then {call}()."
            )

    def step(self, actions: Any):
        self._check_idle("step")
        if isinstance(actions, np.ndarray) and actions.shape[:1] == (self.num_envs,):
            rows: Sequence[Any] = actions  # row i is env i's action, as iterate() would give it
        else:
            rows = self._action_rows(actions, self.num_envs)
        if self._runner is None:
            results = self._step_threads(rows)
            observations = self._batch([r[0] for r in results])
        else:
            results, observations = self._step_native(rows)
        self._autoreset = [r[2] or r[3] for r in results]
        if self._step_arrays is not None:
            return self._fields_step(results, observations)
        rewards = np.array([r[1] for r in results], dtype=np.float64)
        terminations = np.array([r[2] for r in results], dtype=np.bool_)
        truncations = np.array([r[3] for r in results], dtype=np.bool_)
        infos: dict[str, Any] = {}
        for i, result in enumerate(results):
            infos = self._add_info(infos, result[4], i)
        return observations, rewards, terminations, truncations, infos

    def _action_rows(self, actions: Any, count: int) -> list[Any]:
        """``count`` actions, one per env stepped, from a batch.

        Raises:
            InvalidArgumentError: There are more or fewer actions than envs (once, a length check).
        """
        shape = (count, *self.single_action_space.shape)
        try:
            # iterate() only needs the batch's type; the count is checked below, once, with a clear message.
            rows = list(iterate(batch_space(self.single_action_space, max(count, 1)), actions))
        except (TypeError, ValueError) as exc:  # a number, None: not a batch at all
            raise InvalidArgumentError(
                f"Expected {count} actions (one per env, e.g. an array of shape {shape}); "
                f"found {shown(actions)}, which is not a batch ({exc}). Pass vec.action_space.sample() to see one."
            ) from None
        if len(rows) != count:
            raise InvalidArgumentError(
                f"Expected {count} actions (one per env, e.g. an array of shape {shape}); "
                f"found {len(rows)}. Pass one action for each env, in the envs' (or env_ids') order."
            )
        return rows

    # --- the asynchronous mode --------------------------------------------------------------------

    def send(self, actions: Any, env_ids: Any = None) -> None:
        """Start the steps of some envs and return at once; :meth:`recv` collects them.

        Each env's step runs whole on one of the vector env's threads, with the
        same results as :meth:`step` gives (the same trajectories for the same
        seeds). Autoreset is next-step, per env: the ``send`` after the one
        whose step ended an episode resets that env instead (its action is
        ignored), and ``recv`` returns its first observation with reward 0.

        Args:
            actions: One action per env sent, in ``env_ids``' order.
            env_ids: Indices of the envs to step, each once and none still in
                flight; ``None``: all of them.

        Raises:
            InvalidArgumentError: An env id is out of range, not a whole number or given twice, or the
                actions do not match the ids.
            EnvError: An env named is still in flight (sent and not yet received).
        """
        ids = self._in_flight.check_ids(env_ids)
        rows = self._action_rows(actions, len(ids))
        self._in_flight.send(ids, rows, self._step_one)

    @property
    def in_flight(self) -> int:
        """How many envs were sent and not yet received (:meth:`recv` returns them)."""
        return self._in_flight.count

    def recv(self) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict[str, Any], np.ndarray]:
        """The first steps done of the envs sent: up to ``batch_size`` of them, in the order they finished.

        Returns:
            ``(observations, rewards, terminations, truncations, infos, env_ids)``:
            row ``k`` of each (and of every info array) is env ``env_ids[k]``'s.

        Raises:
            EnvError: Nothing was sent (``recv`` before ``send``, or once every env sent came back).
        """
        done = self._in_flight.recv(self.batch_size)
        count = len(done)
        env_ids = np.array([env_id for env_id, _ in done], dtype=np.int64)
        observations = concatenate(
            self.single_observation_space, [r[0] for _, r in done],
            create_empty_array(self.single_observation_space, count),
        )
        rewards = np.array([r[1] for _, r in done], dtype=np.float64)
        terminations = np.array([r[2] for _, r in done], dtype=np.bool_)
        truncations = np.array([r[3] for _, r in done], dtype=np.bool_)
        infos = batch_infos([r[4] for _, r in done])
        return observations, rewards, terminations, truncations, infos, env_ids

    def _step_one(self, i: int, action: Any) -> StepResult:
        """One env's whole step, or its reset if its last step ended an episode (next-step autoreset)."""
        if self._autoreset[i]:
            obs, info = self.envs[i].reset()
            result: StepResult = (obs, 0.0, False, False, info)
        else:
            result = self.envs[i].step(action)  # a retrokit env hands out no buffer it will overwrite while held
        self._autoreset[i] = bool(result[2] or result[3])
        return result

    def _fields_step(self, results: list[tuple], observations: Any) -> tuple:
        """The step's arrays, when every env is a one-player RetroEnv whose info is exactly its fields.

        They come from a pool (see :mod:`retrokit.envs.buffers`) and are filled
        through memoryviews, so a step touches none of numpy's code.
        """
        arrays = self._step_arrays.take()
        rewards, terminations, truncations = arrays.flags
        for i, result in enumerate(results):
            rewards[i], terminations[i], truncations[i] = result[1], result[2], result[3]
        for row, values in zip(arrays.rows, self._field_values):
            row[:] = values  # the env's reader decoded this step's fields (its info's) into it
        arrays.refill_masks()
        return observations, arrays.rewards, arrays.terminations, arrays.truncations, dict(arrays.info)

    def _step_native(self, actions: Sequence[Any]) -> tuple[list[tuple], np.ndarray]:
        envs = self.envs
        batch, views = self._batches.take_rows() if self._batches is not None else (None, [])
        stepping = [i for i in range(self.num_envs) if not self._autoreset[i]]
        for i in stepping:
            self._steppers[i].begin(actions[i])
        steppers = [self._steppers[i] for i in stepping]
        screens = [views[i] for i in stepping] if self._direct_screens else None

        def frames(live: list[int], count: int, after: int) -> tuple[bool, ...]:
            envs_live = [stepping[k] for k in live]
            rows = self._actions if len(envs_live) == self.num_envs else self._actions[envs_live]
            converted = screens is not None and after == 0
            return self._runner.run(envs_live, rows, count, [screens[k] for k in live] if converted else None, after)

        converted = drive(steppers, frames)
        finishing = self._steppings
        results = {i: finishing[i].finish(views[i] if converted[k] else None) for k, i in enumerate(stepping)}
        for i in range(self.num_envs):
            if self._autoreset[i]:
                obs, info = envs[i].reset()
                results[i] = (obs, 0.0, False, False, info)
        ordered = [results[i] for i in range(self.num_envs)]
        if batch is None:
            return ordered, self._batch([r[0] for r in ordered])
        for i, result in enumerate(ordered):
            if result[0] is not views[i]:  # not converted straight into the batch
                batch[i] = result[0]
        return ordered, batch

    def _step_threads(self, actions: Sequence[Any]) -> list[tuple]:
        return self._each(lambda i: self._step_one(i, actions[i]))

    def to_sb3(self) -> Any:
        """This vector env as Stable-Baselines3's ``VecEnv`` (:class:`~retrokit.envs.sb3.SB3VecEnv`), for its algorithms.

        Raises:
            MissingExtraError: stable-baselines3 is not installed.
        """
        try:
            from retrokit.envs.sb3 import SB3VecEnv
        except ImportError as exc:
            raise MissingExtraError(
                f"Expected stable-baselines3 to make an SB3 VecEnv; importing it failed ({exc}). Install it with its "
                "CPU torch: pip install torch --index-url https://download.pytorch.org/whl/cpu stable-baselines3"
            ) from None
        return SB3VecEnv(self)

    def render(self) -> tuple[Any, ...] | None:
        return tuple(env.render() for env in self.envs)

    def close_extras(self, **kwargs: Any) -> None:
        self._in_flight.close()
        self._pool.shutdown(wait=True)
        for env in self.envs:
            env.close()


def available_cpus() -> int:
    """The CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def make_vec(
    game: str,
    num_envs: int,
    state: Any = None,
    scenario: Any = None,
    *,
    threads: int | None = None,
    batch_size: int | None = None,
    **options: Any,
) -> ThreadedVectorEnv:
    """Make ``num_envs`` copies of a game's env stepped on threads (one per CPU unless ``threads`` says).

    ``step`` runs every env's frames in one native call shared by the
    threads (the caller's included); a thread the machine deschedules holds
    up nobody, since the emulators it has not started are run by whichever
    thread is free. The asynchronous mode, ``send(actions, env_ids)`` then
    ``recv()`` (see :meth:`ThreadedVectorEnv.send`), runs each env's whole
    step on ``threads`` threads while the caller goes on; ``batch_size`` is
    how many envs' steps ``recv`` returns at most (the first done). The
    vector env pickles as these arguments: unpickled, it is a fresh one made
    from them (no emulator state or episode carried over).
    """
    from retrokit.envs.env import State, make

    num_envs = check_num_envs(num_envs)
    check_fits(num_envs, (MIN_ENV_BYTES, MIN_ENV_BYTES), at_least=True)  # before a list of num_envs functions
    starts = [State.DEFAULT if s is None else s for s in per_env_states(state, num_envs)]  # a list: one per env
    # partials, not lambdas: the vector env pickles as its env functions
    return ThreadedVectorEnv(
        [functools.partial(make, game, s, scenario, **options) for s in starts], threads, batch_size
    )
