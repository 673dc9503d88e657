"""Rainbow trained by RLlib on Ray (``retrokit train --agent rainbow --backend ray``), its policy the local Rainbow's.

RLlib 2.60's new-stack DQN is configured as the Rainbow config says (:data:`MAPPING`, one line a key), with
its module's layers the local Rainbow's network (:mod:`.rllib_rainbow_module`): the weights a Ray run saves
are the ``state_dict`` that ``evaluate --agent rainbow --init`` loads, key for key. The Ray driver
(:mod:`retrokit.learning.raytrain`) registers the env, builds the algorithm from :func:`algorithm_config`,
trains it and saves :func:`weights_of` and :func:`state_of` through the run folder; ``--resume`` and
``--init`` go through :func:`restore`.

What differs from the local Rainbow (docs/learning.md, "Rainbow on Ray"):

- the envs are ``runners`` x ``envs_per_runner`` (RLlib's env runners, Ray actors over the cluster), not
  ``train_envs``; each env steps ``update_every`` times (more if ``n_step`` is larger: RLlib's fragments must
  hold an n-step return), then the learner makes one update per ``update_every`` steps gathered, as locally;
- the replay is RLlib's prioritized episode replay in the driver: each observation is kept as the env gives
  it, the stacked frames (4 x 7,056 bytes a step), where Tianshou keeps each frame once. It is refused early
  when it does not fit in the memory available (:func:`replay_bytes`);
- RLlib never starts a sampled transition in the last ``n_step - 1`` steps of an episode (it draws again),
  where Tianshou takes a shorter return there: those steps' rewards are learned only inside earlier
  transitions' returns. Its priorities are each transition's loss and its beta stays fixed (RLlib passes the
  config's beta at every sample), as locally.

RLlib is imported inside the functions only: importing this module needs neither Ray nor torch.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from retrokit.errors import InvalidArgumentError
from retrokit.learning.config import check_config
from retrokit.learning.rainbow import KEYS, check_replay_fits

#: Where each key of a Rainbow config goes in RLlib's DQN: a ``DQNConfig`` field (``training(...)``), the
#: module (:class:`~retrokit.learning.rllib_rainbow_module.RainbowModule`), the learner, or the env.
MAPPING: dict[str, str] = {
    "learning_rate": "lr",
    "adam_epsilon": "adam_epsilon (the learner's Adam: RLlib's own ignores it on the new stack)",
    "gamma": "gamma",
    "atoms": "num_atoms (the learner's loss) and the module's heads",
    "v_min": "v_min (the learner's projection) and the module's support",
    "v_max": "v_max (the learner's projection) and the module's support",
    "n_step": "n_step; rollout_fragment_length is at least it",
    "noisy": "the module's heads (RLlib's noisy reaches only its old stack); epsilon 0",
    "noisy_sigma0": "the module's noisy layers (RLlib's sigma0 reaches only its old stack)",
    "dueling": "the module's heads (dueling over the actions, per atom)",
    "replay": "replay_buffer_config.capacity (timesteps, a PrioritizedEpisodeReplayBuffer)",
    "priority_alpha": "replay_buffer_config.alpha",
    "priority_beta": "replay_buffer_config.beta (fixed)",
    "minibatch": "train_batch_size_per_learner (with N learners an update takes N minibatches, N times rarer)",
    "target_update": "target_network_update_freq (env steps over all envs), tau 1",
    "learning_starts": "num_steps_sampled_before_learning_starts",
    "update_every": "rollout_fragment_length and training_intensity: one update per update_every steps",
    "reward_scale": "the env (rainbow.TaskEnv), registered by the driver",
    "frame_size": "the env's native preprocessing (observation_options)",
    "frame_stack": "the env's native preprocessing (observation_options)",
    "grayscale": "the env's native preprocessing (observation_options)",
    "network": "the module (Mnih et al.'s CNN: RainbowNet's)",
    "train_envs": "not used: the envs are runners x envs_per_runner",
}
#: What RLlib's prioritized episode replay takes a step besides its observation: its two segment trees and
#: free-index deque, allocated for the capacity (150 bytes a step), and each step's action, reward, flags and
#: sample index (330 to 530 bytes). Measured with tracemalloc on RLlib 2.60's PrioritizedEpisodeReplayBuffer,
#: fed 16,000 to 32,000 steps in 4-step fragments and in whole episodes; rounded up.
RLLIB_TRANSITION_EXTRA_BYTES = 700


def replay_bytes(config: Mapping[str, Any], size: int) -> int:
    """What RLlib's replay of ``size`` transitions takes: each observation (stacked frames, bytes) and the rest."""
    side = config["frame_size"]
    frame = side * side * (1 if config["grayscale"] else 3)
    return size * (frame * config["frame_stack"] + RLLIB_TRANSITION_EXTRA_BYTES)


def check(config: Mapping[str, Any]) -> None:
    """Refuse, before Ray starts, a replay that would not fit in this process's memory (the Ray driver's).

    Raises:
        InvalidArgumentError: It would not fit.
    """
    check_replay_fits(config["replay"], replay_bytes(config, config["replay"]), " (RLlib's, in the Ray driver)")


def algorithm_config(config: Mapping[str, Any], env: str, runners: int, envs_per_runner: int, seed: int) -> Any:
    """RLlib's DQN (new API stack) configured as the Rainbow ``config``, on the registered env ``env``.

    Args:
        config: A Rainbow config's values (checked by :func:`~retrokit.learning.config.load_config`).
        env: A name registered with ``ray.tune.register_env``, making a :class:`~retrokit.learning.rainbow.TaskEnv`
            with the config's observation options.
        runners: Env runners (Ray actors); 0 steps the envs in the driver.
        envs_per_runner: Envs each runner steps.
        seed: The run's seed.

    Returns:
        A ``DQNConfig``; ``.build_algo()`` makes the algorithm (after ``ray.init``).

    Raises:
        AgentConfigError: ``config`` is not a Rainbow config: a key unknown or missing, a value out of range.
        InvalidArgumentError: Fewer than 0 runners or 1 env a runner, a negative seed, or the replay does not fit
            in memory.
    """
    from ray.rllib.algorithms.dqn import DQNConfig
    from ray.rllib.core.rl_module.rl_module import RLModuleSpec

    from retrokit.learning.rllib_rainbow_module import CONFIG, RainbowLearner, RainbowModule

    values = check_config("rainbow", dict(config), KEYS, "given to RLlib's Rainbow")  # the loader's checks, again
    counts = (runners, envs_per_runner, seed)
    if not all(isinstance(n, int) and not isinstance(n, bool) for n in counts) or runners < 0 or envs_per_runner < 1 \
            or seed < 0:
        raise InvalidArgumentError(
            "Expected 0 or more env runners, 1 or more envs a runner and a seed of 0 or more, whole numbers, got "
            f"{', '.join(repr(n) for n in counts)}."
        )
    check(values)
    fragment = values["update_every"] * math.ceil(values["n_step"] / values["update_every"])
    return (
        DQNConfig()
        .framework("torch")
        .environment(env)
        .env_runners(num_env_runners=runners, num_envs_per_env_runner=envs_per_runner,
                     rollout_fragment_length=fragment)
        .training(
            lr=values["learning_rate"], adam_epsilon=values["adam_epsilon"], gamma=values["gamma"],
            num_atoms=values["atoms"], v_min=values["v_min"], v_max=values["v_max"], n_step=values["n_step"],
            noisy=values["noisy"], sigma0=values["noisy_sigma0"], dueling=values["dueling"], double_q=True,
            train_batch_size_per_learner=values["minibatch"], target_network_update_freq=values["target_update"],
            tau=1.0, num_steps_sampled_before_learning_starts=values["learning_starts"],
            replay_buffer_config={"type": "PrioritizedEpisodeReplayBuffer", "capacity": values["replay"],
                                  "alpha": values["priority_alpha"], "beta": values["priority_beta"]},
            training_intensity=training_intensity(values, fragment, runners, envs_per_runner),
            grad_clip=None,  # Tianshou's Rainbow does not clip (RLlib's DQN clips at 40 by default)
            epsilon=[(0, 0.0)],
        )
        .learners(learner_class=RainbowLearner)
        .rl_module(rl_module_spec=RLModuleSpec(module_class=RainbowModule, model_config={CONFIG: values}))
        .debugging(seed=seed)
    )  # fmt: skip


def training_intensity(values: Mapping[str, Any], fragment: int, runners: int, envs_per_runner: int) -> float:
    """RLlib's ``training_intensity`` that makes one update per ``update_every`` steps gathered.

    A DQN iteration samples one fragment from each env of each runner (of the driver's runner when there are
    none), then updates ``round(intensity / native)`` times, ``native`` being the batch over the steps of
    the runners and the driver (``calculate_rr_weights``): the intensity is that ratio times the updates
    wanted, an integer.
    """
    envs = envs_per_runner * max(runners, 1)
    updates = envs * fragment // values["update_every"]
    native = values["minibatch"] / (fragment * envs_per_runner * max(runners + 1, 1))
    return updates * native


def _module(learner: Any) -> Any:
    """A learner's Rainbow module (the single-agent one)."""
    from ray.rllib.core import DEFAULT_MODULE_ID

    return learner.module[DEFAULT_MODULE_ID].unwrapped()


def _optimizer(learner: Any) -> Any:
    """A learner's Adam (the module's one optimizer)."""
    from ray.rllib.core import DEFAULT_MODULE_ID

    return learner.get_optimizer(DEFAULT_MODULE_ID)


def _network_state(learner: Any) -> dict[str, Any]:
    """A learner's network's tensors, named as the local Rainbow's network names them."""
    return {name: tensor.detach().cpu().clone() for name, tensor in _module(learner).network.state_dict().items()}


def _optimizer_state(learner: Any) -> dict[str, Any]:
    return _optimizer(learner).state_dict()


def weights_of(algorithm: Any) -> bytes:
    """The learner's network as a ``torch.save`` of its ``state_dict``: the local Rainbow's network loads it."""
    import torch

    from retrokit.learning.raytrain import on_learners
    from retrokit.learning.trainrun import state_bytes

    return state_bytes(torch.save, on_learners(algorithm, _network_state))


def state_of(algorithm: Any) -> bytes:
    """The learner's optimizer state (Adam's moments and steps), a ``torch.save`` of tensors and numbers.

    The target network is not kept: a resumed run starts it as the online one, as the local Rainbow does, and
    refills the replay (``learning_starts`` steps) before its next update.
    """
    import torch

    from retrokit.learning.raytrain import on_learners
    from retrokit.learning.trainrun import state_bytes

    return state_bytes(torch.save, on_learners(algorithm, _optimizer_state))


def restore(algorithm: Any, weights: bytes, state: bytes | None) -> None:
    """Load ``weights`` (and the optimizer ``state``, if any) into every learner, then into every env runner.

    The target network starts as the online one.

    Raises:
        PolicyFileError: The bytes are not tensors, or their names or shapes are not this network's, or the
            state is not this optimizer's.
    """
    from retrokit.learning.ppo import load_tensors
    from retrokit.learning.raytrain import load_learners

    load_tensors(weights, "the weights to restore")  # a damaged file is refused here, before any learner
    optimizer = None if state is None else load_tensors(state, "the optimizer state to restore")
    load_learners(algorithm, _load, weights=weights, optimizer=optimizer)


def _load(learner: Any, weights: bytes, optimizer: dict[str, Any] | None) -> None:
    """Load the weights into a learner's network and its target, and the optimizer's state."""
    from retrokit.errors import PolicyFileError
    from retrokit.learning.ppo import load_into

    module = _module(learner)
    load_into(module.network, weights, "the weights to restore")
    for online, target in module.get_target_network_pairs():
        target.load_state_dict(online.state_dict())
    if optimizer is not None:
        try:
            _optimizer(learner).load_state_dict(optimizer)
        except (ValueError, KeyError, TypeError, RuntimeError, IndexError) as exc:
            raise PolicyFileError(
                "Expected the optimizer state to restore to be this Rainbow's Adam's, but it does not fit "
                f"({str(exc).splitlines()[0] if str(exc) else type(exc).__name__}); resume with the run's own "
                "checkpoint."
            ) from None
