"""Rainbow, the paper's value-based baseline, over Tianshou: played on a level for ``evaluate``, trained for ``train``.

The network is Hessel et al.'s: the CNN of Mnih et al. on the stacked gray
frames, then dueling value and advantage heads of 512 noisy units, each giving
a distribution over ``atoms`` returns on ``[v_min, v_max]`` (Tianshou's
``RainbowNet``, its input scaled from bytes to [0, 1]). The algorithm is
Tianshou's ``RainbowDQN`` (distributional loss, n-step returns, the target
network evaluating the online network's choice: double Q) on its
proportional prioritized replay. docs/learning.md says why Tianshou (its
replay keeps each frame once, as bytes: the paper's 0.5M transitions take
3.5 GB, not 56) and what was compared.

Acting and learning follow Hessel et al.'s loop, counted in agent steps: the
envs step ``update_every`` times each, then one minibatch update per env,
once the replay holds ``learning_starts`` transitions; the target network is
copied every ``target_update`` steps. ``evaluate`` plays a level's monitored
env alone (the paper's test runs); ``train`` steps ``train_envs`` envs, each
drawing one of the training levels at every episode (``make()``'s state
weights, seeded), into one replay.

Weights are the network's ``state_dict``, loaded only through
``torch.load(..., weights_only=True)`` into a network built from the config
(:mod:`retrokit.learning.policy`). The replay is not checkpointed: a resumed
``train`` refills it (``learning_starts`` steps) before its next update.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import gymnasium
import numpy as np

from retrokit.errors import InvalidArgumentError
from retrokit.learning.algorithms import VIEW_KEYS, Key, require_libraries
from retrokit.learning.task import TaskEnv, image_options  # TaskEnv: what rainbow.TaskEnv named

if TYPE_CHECKING:
    from retrokit.learning.setup import LearnerSetup
    from retrokit.learning.trainrun import TrainRun

LIBRARY = "tianshou"
MAX_REPLAY = 10_000_000  # 70 GB of 84x84 frames: more is a typo
#: Transitions a zero-shot run keeps (it never samples them).
ZERO_SHOT_REPLAY = 1000
#: A transition's bytes besides its frame: action, reward, flags, index, priority (Tianshou 2.0: about 54).
TRANSITION_EXTRA_BYTES = 64

#: The keys of a Rainbow config: its type, range and meaning (the loader checks every config against it).
KEYS: dict[str, Key] = {
    "learning_rate": Key(float, "Adam's step size", 1e-9, 1.0),
    "adam_epsilon": Key(float, "Adam's epsilon", 1e-12, 1.0),
    "gamma": Key(float, "the discount", 0.0, 1.0),
    "atoms": Key(int, "the atoms of the return distribution", 2, 1001),
    "v_min": Key(float, "the smallest atom's return", -1e9, 1e9),
    "v_max": Key(float, "the largest atom's return", -1e9, 1e9),
    "n_step": Key(int, "the steps of a multi-step return", 1, 1000),
    "noisy": Key(bool, "noisy linear heads (else plain ones, and greedy acting)"),
    "noisy_sigma0": Key(float, "the noisy layers' initial sigma_0", 0.0, 100.0),
    "dueling": Key(bool, "dueling value and advantage heads"),
    "replay": Key(int, "the transitions the replay holds", 1, MAX_REPLAY),
    "priority_alpha": Key(float, "the prioritized replay's priority exponent", 0.0, 10.0),
    "priority_beta": Key(float, "the prioritized replay's importance-sampling exponent (fixed)", 0.0, 1.0),
    "minibatch": Key(int, "the transitions of an update", 1, 65536),
    "target_update": Key(int, "the agent steps between copies of the target network", 1, 1 << 40),
    "learning_starts": Key(int, "the transitions in the replay before the first update", 1, 1 << 40),
    "update_every": Key(int, "the agent steps of an env between updates", 1, 1 << 20),
    **VIEW_KEYS,
    "train_envs": Key(int, "the envs retrokit train steps, each drawing a training level per episode", 1, 256),
}


def check_values(values: Mapping[str, Any]) -> str | None:
    """The problem of a config's keys taken together, or ``None``: the atoms' support must not be empty."""
    if values["v_min"] >= values["v_max"]:
        return f"v_min ({values['v_min']:g}) must be below v_max ({values['v_max']:g})"
    return None


#: The native preprocessing options of the config's frames (PPO's: the same frames).
observation_options = image_options


def require() -> None:
    """Raise :class:`~retrokit.errors.MissingExtraError` unless Tianshou and torch are installed."""
    require_libraries("rainbow", {"tianshou": "Tianshou", "torch": "torch"})


def library() -> str:
    """The library and its version, for ``policy.json``."""
    import tianshou

    return f"{LIBRARY} {tianshou.__version__}"


@dataclass
class Learner:
    """Tianshou's pieces of one Rainbow: the network, the policy, the algorithm."""

    network: Any  # torch.nn.Module
    policy: Any  # tianshou's C51Policy
    algorithm: Any  # tianshou's RainbowDQN


def build(config: Mapping[str, Any], shape: tuple[int, ...], actions: int) -> Learner:
    """A Rainbow of ``config`` for observations of ``shape`` (channels first) and ``actions`` choices."""
    from tianshou.algorithm.modelfree.c51 import C51Policy
    from tianshou.algorithm.modelfree.rainbow import RainbowDQN
    from tianshou.algorithm.optim import AdamOptimizerFactory

    network = build_network(config, shape, actions)
    policy = C51Policy(model=network, action_space=gymnasium.spaces.Discrete(actions), num_atoms=config["atoms"],
                       v_min=config["v_min"], v_max=config["v_max"])
    algorithm = RainbowDQN(
        policy=policy, optim=AdamOptimizerFactory(lr=config["learning_rate"], eps=config["adam_epsilon"]),
        gamma=config["gamma"], n_step_return_horizon=config["n_step"],
        # Tianshou counts the target's period in updates: one per update_every agent steps of an env
        target_update_freq=max(1, round(config["target_update"] / config["update_every"])),
    )  # fmt: skip
    return Learner(network, policy, algorithm)


def build_network(config: Mapping[str, Any], shape: tuple[int, ...], actions: int) -> Any:  # a torch.nn.Module
    """Hessel et al.'s network of ``config`` (Tianshou's ``RainbowNet``, its input scaled from bytes), noisy when acting.

    The one network of every Rainbow: the local one's, and the layers of the RLlib module
    (:mod:`retrokit.learning.rllib_rainbow`), so that a policy trained on either loads in the other.
    """
    from tianshou.env.atari.atari_network import RainbowNet, ScaledObsInputActionReprNet

    channels, height, width = shape
    network = ScaledObsInputActionReprNet(RainbowNet(
        c=channels, h=height, w=width, action_shape=[actions], num_atoms=config["atoms"],
        noisy_std=config["noisy_sigma0"], is_dueling=config["dueling"], is_noisy=config["noisy"],
    ))  # fmt: skip
    if config["noisy"]:
        _act_noisily(network)
    return network


def _act_noisily(network: Any) -> None:  # a torch.nn.Module
    """Make the noisy layers noisy when the agent acts too, and compute them without building their weights.

    Tianshou's collector acts with the network in eval mode, where its ``NoisyLinear`` uses the mean weights
    only: acting would be greedy on them, with no exploration at all (the config's epsilon is 0), unlike Hessel
    et al.'s agent. And its forward builds the noisy weight matrix (512 x 3,136 for the first head) at every
    call: an action took 13 times a plain network's time here. Factorized noise needs no such matrix:
    ``(mu + sigma * outer(eps_q, eps_p)) x = mu x + eps_q * (sigma (eps_p * x))``, two products of the layer's
    size. The noise is drawn again at each update, so it stays the same for ``update_every`` steps.
    """
    from functools import partial

    from tianshou.utils.net.discrete import NoisyLinear

    for layer in network.modules():
        if isinstance(layer, NoisyLinear):
            layer.forward = partial(_noisy_forward, layer)


def _noisy_forward(layer: Any, x: Any) -> Any:  # a NoisyLinear, a tensor -> a tensor
    """``layer``'s output with its current noise, factorized (see :func:`_act_noisily`)."""
    from torch.nn import functional

    noise = functional.linear(x * layer.eps_p, layer.sigma_W) + layer.sigma_bias
    return functional.linear(x, layer.mu_W, layer.mu_bias) + noise * layer.eps_q


def draw_noise(network: Any) -> None:  # a torch.nn.Module
    """Draw new noise for every noisy layer of ``network``."""
    from tianshou.utils.net.discrete import NoisyLinear

    for layer in network.modules():
        if isinstance(layer, NoisyLinear):
            layer.sample()


def replay_bytes(config: Mapping[str, Any], size: int) -> int:
    """What a replay of ``size`` transitions takes: its frames (one a transition when stacked) and the rest."""
    side = config["frame_size"]
    frame = side * side * (1 if config["grayscale"] else 3)
    stacked = config["grayscale"] and config["frame_stack"] > 1
    return size * (frame * (1 if stacked else config["frame_stack"]) + TRANSITION_EXTRA_BYTES)


def check_replay_fits(transitions: int, needed: int, where: str = "") -> None:
    """Refuse a replay of ``transitions`` that takes ``needed`` bytes if the memory available is less.

    It fills as the agent plays: refused now, not killed by the system hours later.

    Raises:
        InvalidArgumentError: It would not fit; ``where`` says where it lives, if not in this process.
    """
    from retrokit.envs.memory import available_memory

    room = available_memory()
    if room is not None and needed > room:
        raise InvalidArgumentError(
            f"Expected Rainbow's replay of {transitions:,} transitions{where} to fit in memory: it takes "
            f"{needed / 2**30:,.1f} GiB, and {max(room, 0) / 2**30:,.1f} GiB are available; use a config with a "
            "smaller replay (quick.yaml keeps 100,000), or a machine with more memory."
        )


def replay(config: Mapping[str, Any], envs: int, size: int | None = None) -> Any:  # a tianshou buffer
    """The prioritized replay: each gray frame stored once, as bytes, the stacks rebuilt when sampled.

    Raises:
        InvalidArgumentError: It would not fit in the memory available (it fills as the agent plays: refused
            now, not killed by the system hours later).
    """
    from tianshou.data import PrioritizedVectorReplayBuffer

    stacked = config["grayscale"] and config["frame_stack"] > 1
    total = max(envs, size or config["replay"])
    check_replay_fits(total, replay_bytes(config, total))
    return PrioritizedVectorReplayBuffer(
        total, buffer_num=envs, ignore_obs_next=True, save_only_last_obs=stacked,
        stack_num=config["frame_stack"] if stacked else 1, alpha=config["priority_alpha"],
        beta=config["priority_beta"],
    )  # fmt: skip


def weights_of(learner: Learner) -> bytes:
    """The network as a ``torch.save`` of its ``state_dict``."""
    import torch

    from retrokit.learning.trainrun import state_bytes

    return state_bytes(torch.save, learner.network.state_dict())


def load_weights(learner: Learner, data: bytes, what: str) -> None:
    """Load a network's weights, the same names and shapes only; the target network starts as the online one.

    Raises:
        PolicyFileError: They are not tensors, or their names or shapes are not this network's.
    """
    from retrokit.learning.ppo import load_into

    learner.algorithm.model_old.load_state_dict(load_into(learner.network, data, what))


def run_steps(learner: Learner, collector: Any, buffer: Any, config: Mapping[str, Any], envs: int, *,
              learn: bool, until: Callable[[int], bool]) -> int:
    """Step the envs ``update_every`` times each, then update once per env, until ``until(steps)`` says stop.

    Returns:
        The agent steps taken (over all envs). In ``evaluate`` the monitor ends the loop (``BudgetSpent``).
    """
    from tianshou.utils.torch_utils import policy_within_training_step, torch_train_mode

    steps = 0
    while not until(steps):
        collector.collect(n_step=config["update_every"] * envs)
        steps += config["update_every"] * envs
        updating = learn and len(buffer) >= config["learning_starts"]
        if config["noisy"] and not updating:
            # New noise as often as an update draws it (Tianshou's update does), before learning starts too, as
            # Hessel et al.'s agent does: one draw for all of it acted on one fixed policy, standing still for whole
            # 1,000-step episodes (the paper config's 20,000 steps before learning scored 0 on every Dasher level)
            draw_noise(learner.network)
        if updating:
            with policy_within_training_step(learner.policy), torch_train_mode(learner.policy):
                for _ in range(envs):
                    learner.algorithm.update(buffer=buffer, sample_size=config["minibatch"])
    return steps


def seed_all(seed: int) -> None:
    """Seed torch, numpy and random (the envs' first resets are seeded by their runner)."""
    import random

    import torch

    random.seed(seed)
    np.random.seed(seed % 2**32)
    torch.manual_seed(seed)


def play(env: gymnasium.Env, budget: int, seed: int, setup: LearnerSetup) -> None:
    """Play one level's monitored env until its budget is spent, learning as the paper's test runs did.

    Without learning (``setup.learn`` false), the start policy acts (its noisy network sampled) unchanged.
    """
    from tianshou.data import Collector
    from tianshou.env import DummyVectorEnv

    seed_all(seed)
    config = setup.config.values
    task_env = TaskEnv(env, setup.task, config["reward_scale"])
    learner = build(config, task_env.observation_space.shape, task_env.action_space.n)
    policy = setup.start_policy()
    if policy is not None:
        load_weights(learner, policy.read_weights(), f"the start policy {policy.weights_path}")
    buffer = replay(config, 1, None if setup.learn else ZERO_SHOT_REPLAY)
    collector = Collector(learner.algorithm, DummyVectorEnv([lambda: task_env]), buffer, exploration_noise=True)
    collector.reset()
    run_steps(learner, collector, buffer, config, 1, learn=setup.learn, until=lambda _: False)  # the monitor ends it


def train(run: TrainRun, *, threads: int | None = None) -> None:
    """Train one policy on the run's levels: ``train_envs`` envs, each drawing a level at every episode.

    The levels of each game are one env's state weights (equal), so every reset draws one of them from the env's
    seeded generator; envs go round the games when the levels are of several. ``threads`` is unused: the envs
    step in this process, one after another, as Tianshou's ``DummyVectorEnv`` steps them.
    """
    import torch
    from tianshou.data import Collector
    from tianshou.env import DummyVectorEnv

    from retrokit.envs.env import make
    from retrokit.learning.ppo import load_tensors
    from retrokit.learning.trainrun import state_bytes

    training = run.training
    config = training.config.values
    options = {**training.benchmark.env_options(), **observation_options(config)}
    scenario = options.pop("scenario", None)
    states: dict[str, dict[str, float]] = {}
    names: dict[tuple[str, str], str] = {}
    for level in training.levels:
        states.setdefault(level.game, {})[level.state] = 1.0
        names[(level.game, level.state)] = level.name
    games = list(states)
    count = config["train_envs"]

    def ended(env: gymnasium.Env, reward: float, steps: int) -> None:
        base = env.unwrapped
        run.episode(names[(base.game.name, base.state_name)], reward, steps)

    def env_fn(index: int) -> Callable[[], gymnasium.Env]:
        game = games[index % len(games)]
        return lambda: TaskEnv(make(game, states[game], scenario, **options), run.task, config["reward_scale"], ended)

    seed_all(training.seed)
    envs = DummyVectorEnv([env_fn(i) for i in range(count)])
    try:
        envs.seed([training.seed + i for i in range(count)])
        first = envs.observation_space[0]
        learner = build(config, first.shape, len(run.task.actions))
        saved = run.resume_state()
        if saved is not None:
            load_weights(learner, saved[0], f"the checkpoint in {run.path}")
            learner.algorithm.optim.load_state_dict(load_tensors(saved[1], f"the checkpoint's state in {run.path}"))
        elif training.init is not None:
            load_weights(learner, training.init.read_weights(), f"the start policy {training.init.weights_path}")
        buffer = replay(config, count)
        collector = Collector(learner.algorithm, envs, buffer, exploration_noise=True)
        collector.reset()
        spec = {"shape": list(first.shape), "dtype": str(first.dtype), "options": observation_options(config)}
        name = library()
        done = run.timesteps

        def save(timesteps: int) -> None:
            run.save(timesteps, weights_of(learner), state_bytes(torch.save, learner.algorithm.optim.state_dict()),
                     spec, name)

        def until(steps: int) -> bool:
            if steps and run.updated(done + steps):
                save(done + steps)
            return done + steps >= training.timesteps

        steps = run_steps(learner, collector, buffer, config, count, learn=True, until=until)
        save(done + steps)
    finally:
        envs.close()

