"""PPO on RLlib (its new API stack), for ``retrokit train --backend ray``: the same network as the local PPO.

The driver loop (connect, env, train, curve, checkpoints) is :mod:`.raytrain`'s;
this module is what is PPO's in it, the four functions every RLlib agent gives:
:func:`algorithm_config`, :func:`weights_of`, :func:`state_of` and :func:`restore`.

The network is :func:`retrokit.learning.ppo.network`, SB3's
``ActorCriticCnnPolicy`` (the Nature CNN, its features shared by ``action_net``
and ``value_net``), held whole by an RLModule (:class:`SharedCnnModule`), so the
weights RLlib trains are the ``state_dict`` the local PPO saves and
``retrokit evaluate --agent ppo --init DIR`` loads; no RLlib checkpoint (a
pickle) is written or read. The config's keys map onto RLlib's by
:data:`HYPER_PARAMETERS`; :data:`SB3_DEFAULTS` sets what RLlib would otherwise
do differently from SB3's PPO (docs/learning.md, "Joint PPO on a Ray cluster").
This module imports RLlib: only ``train --backend ray`` loads it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import torch
from ray.rllib.algorithms.algorithm import Algorithm
from ray.rllib.algorithms.ppo import PPOConfig
from ray.rllib.algorithms.ppo.torch.ppo_torch_learner import PPOTorchLearner
from ray.rllib.core import DEFAULT_MODULE_ID
from ray.rllib.core.columns import Columns
from ray.rllib.core.rl_module.apis import ValueFunctionAPI
from ray.rllib.core.rl_module.rl_module import RLModuleSpec
from ray.rllib.core.rl_module.torch import TorchRLModule

from retrokit.learning import ppo
from retrokit.learning.raytrain import load_learners, on_learners
from retrokit.learning.trainrun import state_bytes

#: The PPO config's keys as RLlib's ``PPOConfig`` arguments: key -> (the ``PPOConfig`` method, its argument).
#: ``horizon`` is each env's rollout fragment; the batch of an update is every env's (see :func:`algorithm_config`).
HYPER_PARAMETERS: dict[str, tuple[str, str]] = {
    "horizon": ("env_runners", "rollout_fragment_length"),
    "epochs": ("training", "num_epochs"),
    "minibatch": ("training", "minibatch_size"),
    "gamma": ("training", "gamma"),
    "gae_lambda": ("training", "lambda_"),
    "clip": ("training", "clip_param"),
    "entropy": ("training", "entropy_coeff"),
    "value_coef": ("training", "vf_loss_coeff"),
    "max_grad_norm": ("training", "grad_clip"),
    "learning_rate": ("training", "lr"),
}

#: RLlib's PPO arguments set to what SB3's PPO does: no KL penalty (SB3 has none), no clipping of the value loss
#: (SB3's ``clip_range_vf=None``; RLlib clips it at 10 by default), the gradients clipped by their global norm
#: (SB3's ``clip_grad_norm_``).
SB3_DEFAULTS: dict[str, Any] = {"use_kl_loss": False, "vf_clip_param": math.inf, "grad_clip_by": "global_norm"}

#: Adam's epsilon in SB3's PPO (its policies' ``optimizer_kwargs``' default); torch's, RLlib's, is 1e-8.
ADAM_EPSILON = 1e-5


class SharedCnnModule(TorchRLModule, ValueFunctionAPI):
    """An RLModule whose layers are the local PPO's network (:func:`retrokit.learning.ppo.network`).

    ``model_config`` is the PPO config's values. The observations are the env's bytes; SB3's policy scales them
    to [0, 1] itself (``extract_features``), as it does under the local PPO.
    """

    def setup(self) -> None:
        self.policy = ppo.network(self.observation_space, self.action_space, self.model_config)

    def _features(self, batch: dict[str, Any]) -> Any:
        return self.policy.extract_features(batch[Columns.OBS])

    def _logits(self, features: Any) -> Any:
        latent, _ = self.policy.mlp_extractor(features)
        return self.policy.action_net(latent)

    def _forward(self, batch: dict[str, Any], **kwargs: Any) -> dict[str, Any]:
        return {Columns.ACTION_DIST_INPUTS: self._logits(self._features(batch))}

    def _forward_train(self, batch: dict[str, Any], **kwargs: Any) -> dict[str, Any]:
        features = self._features(batch)  # shared with compute_values, as the local PPO's one pass is
        return {Columns.ACTION_DIST_INPUTS: self._logits(features), Columns.EMBEDDINGS: features}

    def compute_values(self, batch: dict[str, Any], embeddings: Any | None = None) -> Any:
        features = self._features(batch) if embeddings is None else embeddings
        _, latent = self.policy.mlp_extractor(features)
        return self.policy.value_net(latent).squeeze(-1)


class SB3AdamLearner(PPOTorchLearner):
    """RLlib's PPO learner with Adam's epsilon of SB3's PPO (:data:`ADAM_EPSILON`)."""

    def configure_optimizers_for_module(self, module_id: str, config: Any = None) -> None:
        params = self.get_parameters(self._module[module_id])
        self.register_optimizer(module_id=module_id, optimizer=torch.optim.Adam(params, eps=ADAM_EPSILON),
                                params=params, lr_or_lr_schedule=config.lr)


def algorithm_config(config: Mapping[str, Any], env: str, runners: int, envs_per_runner: int,
                     seed: int) -> PPOConfig:
    """RLlib's PPO of the config: ``runners`` env runners of ``envs_per_runner`` envs of the registered ``env``.

    Every update is over one fragment of ``horizon`` timesteps from each env of every runner (the paper's joint
    PPO: its batch is each worker's horizon), in minibatches of ``minibatch`` for ``epochs`` passes.
    """
    groups: dict[str, dict[str, Any]] = {"training": dict(SB3_DEFAULTS), "env_runners": {}}
    for key, (group, name) in HYPER_PARAMETERS.items():
        groups[group][name] = config[key]
    groups["training"]["train_batch_size_per_learner"] = config["horizon"] * runners * envs_per_runner
    return (
        PPOConfig()
        .environment(env)
        .framework("torch")
        .env_runners(num_env_runners=runners, num_envs_per_env_runner=envs_per_runner,
                     create_env_on_local_worker=False, batch_mode="truncate_episodes", **groups["env_runners"])
        .training(**groups["training"])
        .learners(num_learners=0, learner_class=SB3AdamLearner)  # the driver learns: the cluster's CPUs step the envs
        .rl_module(rl_module_spec=RLModuleSpec(module_class=SharedCnnModule, model_config=dict(config)))
        .debugging(seed=seed)
    )  # fmt: skip


def weights_of(algorithm: Algorithm) -> bytes:
    """The learner's network as :func:`retrokit.learning.ppo.weights_of` writes it (its ``state_dict``)."""
    return on_learners(algorithm,
                       lambda learner: state_bytes(torch.save, learner.module[DEFAULT_MODULE_ID].policy.state_dict()))


def state_of(algorithm: Algorithm) -> bytes:
    """The learner's training state: its Adam's ``state_dict``."""
    return on_learners(algorithm, lambda learner: state_bytes(torch.save, learner.get_optimizer().state_dict()))


def restore(algorithm: Algorithm, weights: bytes, state: bytes | None) -> None:
    """Load ``weights`` (and the optimizer's ``state``, if any) into every learner, then into every env runner.

    Raises:
        PolicyFileError: They are not this config's network's tensors (loaded with ``weights_only=True``).
    """
    optimizer = None if state is None else ppo.load_tensors(state, "the optimizer state to restore")

    def load(learner: Any) -> None:
        ppo.load_into(learner.module[DEFAULT_MODULE_ID].policy, weights, "the weights to restore")
        if optimizer is not None:
            learner.get_optimizer().load_state_dict(optimizer)

    load_learners(algorithm, load)

