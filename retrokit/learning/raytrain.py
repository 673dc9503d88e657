"""``retrokit train --backend ray``: a learning agent trained jointly by RLlib, its env runners over a Ray cluster.

The driver (this process) connects to Ray the way ``evaluate --backend ray``
does (:func:`retrokit.benchmark.ray_backend.connected`: the address tried
first, a clear error if nothing answers), registers the env, builds RLlib's
algorithm and learns in this process, while ``--env-runners`` env runners (one
CPU each, wherever the cluster has one) play: runner ``i`` (RLlib's
``worker_index``, from 1) plays training level ``(i - 1) mod L`` with the
config's ``train_envs_per_level`` envs (1 if the config has no such key), so
every level is played by as many runners, and every update is over all of
them (the paper's joint training). Before anything starts, the runners' env
is made once here (a bad option is one line), and the cluster must have a
CPU for each runner (RLlib would wait for the others without end).

A runner's env is the level's env (:func:`retrokit.envs.env.make` with the
benchmark's rules and the config's native preprocessing) as the learner sees it
(:class:`~retrokit.learning.task.TaskEnv`). Each finished episode is sent, with
its level, benchmark reward and steps, to a small actor on this node
(:class:`EpisodeLog`), which the driver empties into the run's ``curve.csv``
after each update. A runner lost with its node is started again by RLlib
(``restart_failed_env_runners``) on the nodes left; the update waits for enough
timesteps from the runners alive, so the run still ends with all its timesteps.

Checkpoints, ``--resume`` and ``policy.json`` are :class:`~retrokit.learning.trainrun.TrainRun`'s, as for the
local backend: the weights and optimizer state are torch ``state_dict`` s that the agent's module
(:data:`AGENTS`) reads from and loads into the algorithm; RLlib's own checkpoints (pickles) are never written.
"""

from __future__ import annotations

import importlib
import uuid
from collections.abc import Iterator
from contextlib import contextmanager
from functools import partial
from types import ModuleType
from typing import TYPE_CHECKING, Any

from retrokit.errors import BackendUnavailableError, InvalidArgumentError, MissingExtraError
from retrokit.learning.algorithms import algorithm

if TYPE_CHECKING:
    from retrokit.learning.trainrun import Training, TrainRun

#: The agents RLlib trains, by ``--agent``: the module of each, which gives ``algorithm_config(config, env,
#: runners, envs_per_runner, seed)``, ``weights_of(algorithm)``, ``state_of(algorithm)`` and
#: ``restore(algorithm, weights, state)`` (see :mod:`.rllib_ppo`).
AGENTS = {
    "ppo": "retrokit.learning.rllib_ppo",
    "rainbow": "retrokit.learning.rllib_rainbow",
}
#: The agents whose RLlib module has checks to make before Ray starts, in ``check(config)``: the Rainbow's
#: replay lives in this process. (PPO's module imports RLlib, so it is not asked here.)
PRE_CHECKS = {"rainbow"}
#: The most env runners a run asks for: the paper's 188 workers as 4 runners a level need 188; more is a typo.
MAX_ENV_RUNNERS = 4096
#: What an env runner's process takes: 535 MB resident measured (torch, RLlib, SB3 and the emulator), rounded up.
RUNNER_BYTES = 600 << 20
#: Seconds RLlib waits before starting a failed env runner again (its default, 60, would idle the run that long).
RESTART_DELAY_SECONDS = 2.0


def check(training: Training, address: str | None) -> None:
    """Refuse, before anything starts (Ray, RLlib's import, the run folder), what the run could not do.

    Raises:
        InvalidArgumentError: ``env_runners`` is not a multiple of the levels, a local Ray's runners (or the
            agent's replay, in this process) would not fit in this machine's memory, or the env cannot be made.
        BackendUnavailableError: Nothing answers at ``address``.
    """
    levels, runners = len(training.levels), training.env_runners
    if runners is None or not 1 <= runners <= MAX_ENV_RUNNERS or runners % levels:
        raise InvalidArgumentError(
            f"Expected --env-runners to be a multiple of the {levels} level(s) trained on (so each level has as many "
            f"runners) up to {MAX_ENV_RUNNERS}, got {runners}; use {levels} (the default) or {2 * levels}."
        )
    if training.agent in PRE_CHECKS:
        rllib_module(training.agent).check(training.config.values)
    if address:
        from retrokit.benchmark.ray_backend import check_address

        check_address(address)
    else:
        _check_local_memory(runners)
    # The env every runner makes, made here once: a bad option is this process's one-line error, not the death of
    # every runner, which RLlib reports as an IndexError of its own.
    from retrokit.envs.env import make

    options, scenario = env_options(training)
    make(training.levels[0].game, training.levels[0].state, scenario, **options).close()


def _check_local_memory(runners: int) -> None:
    """Refuse a local Ray whose runners would not fit in this machine's memory (each is a process of its own).

    Raises:
        InvalidArgumentError: They would not.
    """
    from retrokit.envs.memory import available_memory

    room = available_memory()
    if room is not None and runners * RUNNER_BYTES > room:
        raise InvalidArgumentError(
            f"Expected room for the {runners} env runners of a local Ray (about {RUNNER_BYTES >> 20} MiB each: "
            f"torch and RLlib in every runner's process), but this machine has {room >> 20:,} MiB available; "
            "use a Ray cluster (--ray-address), fewer levels (--levels), or --backend local."
        )


def env_options(training: Training) -> tuple[dict[str, Any], Any]:
    """The options of every runner's env (the benchmark's rules, the config's native preprocessing), and its scenario."""
    options = {**training.benchmark.env_options(),
               **algorithm(training.agent).observation_options(training.config.values)}
    return options, options.pop("scenario", None)


@contextmanager
def cluster(training: Training, address: str | None) -> Iterator[Any]:
    """Ray, connected (:func:`~retrokit.benchmark.ray_backend.connected`) and checked to have a CPU for each runner.

    A local Ray is started with as many CPUs as runners. On a cluster with fewer, RLlib would wait for the runners
    it cannot place without end: refused instead, before the run folder is claimed.

    Raises:
        BackendUnavailableError: Ray cannot be reached, or the cluster has fewer CPUs than env runners.
    """
    from retrokit.benchmark.ray_backend import connected

    runners = training.env_runners or 1
    with connected(address, runners) as ray:
        cpus = ray.cluster_resources().get("CPU", 0)
        if cpus < runners:
            fits = int(cpus) // len(training.levels) * len(training.levels)
            where = address or "this process joined"
            raise BackendUnavailableError(
                f"Expected a CPU for each of the {runners} env runners on the Ray cluster at {where}, but it has "
                f"{cpus:g}; add nodes, or use --env-runners {fits or len(training.levels)}."
            )
        yield ray


def require(agent: str) -> None:
    """Raise :class:`~retrokit.errors.MissingExtraError` unless the agent's libraries and RLlib are installed."""
    algorithm(agent).require()
    try:
        import ray.rllib  # noqa: F401 - the check
    except ImportError as exc:
        raise MissingExtraError(
            f"Expected RLlib for --agent {agent} --backend ray, but importing it failed ({exc}); run "
            "`pip install 'ray[rllib]'`, on every node of the cluster too."
        ) from None


def rllib_module(agent: str) -> ModuleType:
    """The RLlib module of ``agent`` (see :data:`AGENTS`)."""
    return importlib.import_module(AGENTS[agent])


def library() -> str:
    """The library and its version, for ``policy.json``."""
    import ray

    return f"ray[rllib] {ray.__version__}"


def on_learners(algorithm: Any, call: Any, **kwargs: Any) -> Any:  # RLlib's Algorithm
    """``call(learner, **kwargs)`` on every learner of ``algorithm``; the first's answer (all hold one network).

    Raises:
        Exception: A learner's call raised it (a :class:`~retrokit.errors.PolicyFileError` of a load, ...).
    """
    answers = [result.get() for result in algorithm.learner_group.foreach_learner(call, **kwargs)]
    if not answers:
        raise RuntimeError("RLlib's algorithm has no learner")
    return answers[0]


def load_learners(algorithm: Any, load: Any, **kwargs: Any) -> None:  # RLlib's Algorithm
    """``load(learner, **kwargs)`` on every learner, then the learners' weights sent to every env runner."""
    on_learners(algorithm, load, **kwargs)
    algorithm.env_runner_group.sync_weights(from_worker_or_learner_group=algorithm.learner_group,
                                            inference_only=True)


class EpisodeLog:
    """A Ray actor on the driver's node that collects the runners' finished episodes until the driver takes them."""

    def __init__(self) -> None:
        self.episodes: list[tuple[str, float, int]] = []

    def add(self, level: str, reward: float, steps: int) -> None:
        self.episodes.append((level, reward, steps))

    def take(self) -> list[tuple[str, float, int]]:
        taken, self.episodes = self.episodes, []
        return taken


def make_env(spec: dict[str, Any], context: Any) -> Any:  # RLlib's EnvContext -> a gymnasium.Env
    """The env of an env runner: its level's, as the learner sees it, reporting each episode to the log.

    ``spec`` is plain data (it travels to every node inside the registered creator).
    """
    import ray

    from retrokit.envs.env import make
    from retrokit.learning.task import TaskEnv

    index = (context.worker_index - 1) % len(spec["levels"])
    game, state = spec["levels"][index]
    name = f"{game}/{state}"
    log = ray.get_actor(spec["log"])

    def ended(_env: Any, reward: float, steps: int) -> None:
        ray.get(log.add.remote(name, reward, steps))  # waited for: a sample's episodes are all logged when it ends

    env = make(game, state, spec["scenario"], **spec["options"])
    return TaskEnv(env, spec["task"], spec["reward_scale"], ended)


def train(run: TrainRun, address: str | None) -> None:
    """Train the run's agent on Ray (see the module's doc); the run's checkpoints and curve as the local backend's."""
    from ray.tune.registry import register_env

    from retrokit.benchmark.ray_backend import connected, on_this_node

    training = run.training
    agent = rllib_module(training.agent)
    config = training.config.values
    runners = training.env_runners
    options, scenario = env_options(training)
    with connected(address, runners) as ray:
        name = f"retrokit-{uuid.uuid4().hex}"
        log = ray.remote(EpisodeLog).options(name=name, **on_this_node(ray)).remote()
        try:
            spec = {"levels": [(level.game, level.state) for level in training.levels], "options": options,
                    "scenario": scenario, "task": run.task, "reward_scale": config["reward_scale"], "log": name}
            register_env(name, partial(make_env, spec))
            settings = agent.algorithm_config(config, name, runners, config.get("train_envs_per_level", 1),
                                              training.seed)
            # An iteration samples at least RLlib's minimum (DQN's: 1,000 steps), no more than the run has left
            least = min(settings.min_sample_timesteps_per_iteration or 0, max(1, training.timesteps - run.timesteps))
            algo = _build(settings.reporting(min_sample_timesteps_per_iteration=least), runners)
            try:
                _train(run, agent, algo, log)
            finally:
                algo.stop()
        finally:
            ray.kill(log)


def _build(settings: Any, runners: int) -> Any:  # RLlib's AlgorithmConfig -> its Algorithm
    """The algorithm of ``settings``, with the fault tolerance of a run over a cluster.

    Raises:
        BackendUnavailableError: The env runners did not start.
    """
    settings.fault_tolerance(restart_failed_env_runners=True, delay_between_env_runner_restarts_s=RESTART_DELAY_SECONDS)
    # No time limit on a sample (RLlib's is 60 s, past which it drops what was played): a fragment of the
    # paper's horizon, 8,192 steps, takes minutes on a CPU. A runner lost with its node answers with an error.
    settings.env_runners(sample_timeout_s=None)
    try:
        return settings.build_algo()
    except Exception as exc:  # noqa: BLE001 - whatever a runner's death makes RLlib raise (an IndexError, ...)
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        raise BackendUnavailableError(
            f"Expected RLlib's {runners} env runners to start on the Ray cluster, but they did not "
            f"({type(exc).__name__}: {first}); every node needs retrokit, RLlib and the benchmark's ROMs, and "
            "Ray's logs of the runners say what failed."
        ) from None


def _train(run: TrainRun, agent: ModuleType, algo: Any, log: Any) -> None:
    """The training loop: an update, its episodes into the curve, a checkpoint when due; until the timesteps."""
    import ray
    from ray.rllib.core import DEFAULT_MODULE_ID
    from ray.rllib.utils.metrics import ENV_RUNNER_RESULTS, NUM_ENV_STEPS_SAMPLED_LIFETIME

    training = run.training
    start = run.timesteps
    saved = run.resume_state()
    if saved is not None:
        agent.restore(algo, *saved)
    elif training.init is not None:
        agent.restore(algo, training.init.read_weights(), None)
    space = next(iter(algo.learner_group.foreach_learner(
        lambda learner: learner.module[DEFAULT_MODULE_ID].observation_space))).get()
    observation = {"shape": list(space.shape), "dtype": str(space.dtype),
                   "options": algorithm(training.agent).observation_options(training.config.values)}
    made_by = library()

    def save(timesteps: int) -> None:
        run.save(timesteps, agent.weights_of(algo), agent.state_of(algo), observation, made_by)

    timesteps = start
    while timesteps < training.timesteps:
        result = algo.train()
        # RLlib's count of this algorithm's timesteps (absent after an update no runner could sample for)
        timesteps = start + int(result.get(ENV_RUNNER_RESULTS, {}).get(NUM_ENV_STEPS_SAMPLED_LIFETIME, timesteps - start))
        for level, reward, steps in ray.get(log.take.remote()):
            run.episode(level, reward, steps, timesteps)
        if run.updated(timesteps) and timesteps < training.timesteps:
            save(timesteps)
    save(timesteps)
