"""RLlib's side of Rainbow on Ray: a DQN module whose layers are the local Rainbow's network, and its learner.

Imported only by :mod:`retrokit.learning.rllib_rainbow`'s functions (it imports RLlib and torch): Ray builds
these classes by name in each env runner and learner, so they live in a module, not in a function.

:class:`RainbowModule` is RLlib's new-stack DQN module (:class:`DefaultDQNTorchRLModule`: its acting, its
training pass with double Q) with the encoder and heads replaced by one network built by
:func:`retrokit.learning.rainbow.build_network`: Tianshou's ``RainbowNet``, noisy dueling distributional
heads, the same object the local Rainbow trains. So the module's ``network`` state dict IS the local
policy's, key for key; nothing is converted. RLlib 2.60's own DQN module has no noisy layers on the new API
stack (``noisy`` and ``sigma0`` only reach its old stack), and its dueling heads centre the advantage's
logits over the atoms and add one value, where Hessel et al. (and Tianshou) centre over the actions and add a
value distribution.

:class:`RainbowLearner` is RLlib's DQN learner (its distributional loss, priorities, target copies) with the
config's Adam epsilon: RLlib's torch learner builds ``Adam(params)`` with torch's default 1e-8, whatever
``adam_epsilon`` says.
"""

from __future__ import annotations

from typing import Any

import torch
from ray.rllib.algorithms.dqn.default_dqn_rl_module import ATOMS, QF_LOGITS, QF_PREDS, QF_PROBS
from ray.rllib.algorithms.dqn.torch.default_dqn_torch_rl_module import DefaultDQNTorchRLModule
from ray.rllib.algorithms.dqn.torch.dqn_torch_learner import DQNTorchLearner
from ray.rllib.core.columns import Columns
from ray.rllib.core.learner.utils import make_target_network
from ray.rllib.core.rl_module.torch.torch_rl_module import TorchRLModule
from ray.rllib.utils.schedules.scheduler import Scheduler

from retrokit.learning import rainbow

#: The model config's key of the Rainbow config's values.
CONFIG = "rainbow"


class RainbowModule(DefaultDQNTorchRLModule):
    """RLlib's DQN module on the local Rainbow's network (see the module's doc)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.pop("catalog_class", None)  # no catalog: RLlib's encoders and heads are not built
        TorchRLModule.__init__(self, *args, **kwargs)

    def setup(self) -> None:
        config = self.model_config[CONFIG]
        self.uses_dueling = config["dueling"]
        self.uses_double_q = True  # the learner's double_q decides; the module's training pass always gives both
        self.num_atoms, self.v_min, self.v_max = config["atoms"], config["v_min"], config["v_max"]
        # Exploration is the noisy layers' (epsilon 0, as the local Rainbow): greedy on the noisy network.
        self.epsilon_schedule = Scheduler(fixed_value_or_schedule=0.0, framework="torch")
        self.network = rainbow.build_network(config, tuple(self.observation_space.shape), int(self.action_space.n))
        self.noisy, self.redraw_every, self.acted = config["noisy"], config["update_every"], 0

    def get_non_inference_attributes(self) -> list[str]:
        return ["_target_network"]

    def make_target_networks(self) -> None:
        self._target_network = make_target_network(self.network)

    def get_target_network_pairs(self) -> list[tuple[Any, Any]]:
        return [(self.network, self._target_network)]

    def get_initial_state(self) -> dict:
        return {}

    def forward_target(self, batch: dict[str, Any]) -> dict[str, Any]:
        return self._qf_forward_helper(batch, self._target_network, None)

    def compute_q_values(self, batch: dict[str, Any]) -> dict[str, Any]:
        return self._qf_forward_helper(batch, self.network, None)

    def _forward_train(self, batch: dict[str, Any]) -> dict[str, Any]:
        # New noise for the online and the target network at each update, as Tianshou's Rainbow draws it; the env
        # runners get it with the weights (the noise is a parameter), and draw their own in between.
        rainbow.draw_noise(self.network)
        rainbow.draw_noise(self._target_network)
        return super()._forward_train(batch)

    def _forward_exploration(self, batch: dict[str, Any], t: int) -> dict[str, Any]:
        # An env runner draws new noise every update_every steps, as the local Rainbow acts: before learning starts
        # too, where one draw (no update syncs another) acted on one fixed policy for all of it. Updates' noise
        # comes with the weights after each sync.
        self.acted += 1
        if self.noisy and self.acted % self.redraw_every == 0:
            rainbow.draw_noise(self.network)
        return super()._forward_exploration(batch, t)

    def _qf_forward_helper(self, batch: dict[str, Any], encoder: Any, head: Any) -> dict[str, Any]:
        """The Q-values, logits, probabilities and atoms of ``encoder`` (a network of ``build_network``).

        ``RainbowNet.forward`` gives the probabilities only; RLlib's loss takes logits (a cross-entropy), so
        the same layers are run here up to the logits, as ``RainbowNet.forward`` runs them.
        """
        net = encoder.module  # the RainbowNet inside the input scaling
        features = net.net(batch[Columns.OBS].float() / encoder.denom)
        q = net.Q(features).view(-1, net.action_num, net.num_atoms)
        logits = q - q.mean(dim=1, keepdim=True) + net.V(features).view(-1, 1, net.num_atoms) if self.uses_dueling \
            else q
        probs = torch.softmax(logits, dim=-1)
        atoms = torch.linspace(self.v_min, self.v_max, self.num_atoms, device=probs.device)  # C51Policy's support
        return {QF_PREDS: (probs * atoms).sum(dim=-1), QF_LOGITS: logits, QF_PROBS: probs, ATOMS: atoms}


class RainbowLearner(DQNTorchLearner):
    """RLlib's DQN learner with Adam's epsilon from the config, over the trainable parameters only."""

    def configure_optimizers_for_module(self, module_id: str, config: Any = None) -> None:
        module = self._module[module_id]
        # The target network and the noise are parameters that never learn: left out of Adam.
        params = [param for param in self.get_parameters(module) if param.requires_grad]
        self.register_optimizer(module_id=module_id, optimizer=torch.optim.Adam(params, eps=config.adam_epsilon),
                                params=params, lr_or_lr_schedule=config.lr)
