"""PPO, the paper's baseline, over Stable-Baselines3: played on a level for ``evaluate``, trained jointly for ``train``.

The network is SB3's ``CnnPolicy``: the Nature CNN of Mnih et al. (2015) on the
stacked gray frames, its 512 features shared by the policy and the value heads,
as in the baselines' CNN policy. A config (``configs/ppo/*.yaml``) sets the
hyper-parameters; :data:`KEYS` is their table. ``evaluate`` plays one level's env
through a ``DummyVecEnv`` (the paper's test runs had one worker), learning as it
goes, or, zero-shot, samples the start policy's actions without learning.
``train`` runs ``train_envs_per_level`` envs of each training level in retrokit's
native vector env, and every update is over all of them (the paper's joint PPO).

Weights are saved as the policy's ``state_dict`` and loaded only with
``torch.load(..., weights_only=True)`` into a network built from the config
(see :mod:`retrokit.learning.policy`); SB3's own ``model.zip`` (which unpickles)
is never read.
"""

from __future__ import annotations

import io
from collections.abc import Mapping
from functools import partial
from typing import TYPE_CHECKING, Any

from retrokit.errors import PolicyFileError
from retrokit.learning.algorithms import VIEW_KEYS, Key, require_libraries
from retrokit.learning.task import image_options

if TYPE_CHECKING:
    import gymnasium

    from retrokit.learning.setup import LearnerSetup
    from retrokit.learning.trainrun import TrainRun

LIBRARY = "stable-baselines3"
MAX_SIZE = 1 << 20

#: The keys of a PPO config: its type, range and meaning (the loader checks every config against it).
KEYS: dict[str, Key] = {
    "horizon": Key(int, "the timesteps each env plays between updates (SB3's n_steps)", 1, MAX_SIZE),
    "epochs": Key(int, "the passes over each batch (n_epochs)", 1, 1000),
    "minibatch": Key(int, "the samples of a gradient step (batch_size)", 2, MAX_SIZE * 64),
    "gamma": Key(float, "the discount", 0.0, 1.0),
    "gae_lambda": Key(float, "GAE's lambda", 0.0, 1.0),
    "clip": Key(float, "PPO's clip range", 0.0, 10.0),
    "entropy": Key(float, "the entropy bonus's coefficient (ent_coef)", 0.0, 10.0),
    "value_coef": Key(float, "the value loss's coefficient (vf_coef)", 0.0, 100.0),
    "max_grad_norm": Key(float, "the gradients' clipping norm", 0.0, 1e6),
    "learning_rate": Key(float, "Adam's step size", 1e-9, 1.0),
    **VIEW_KEYS,
    "train_envs_per_level": Key(int, "the envs of each training level that retrokit train runs", 1, 64),
}


def observation_options(config: Mapping[str, Any]) -> dict[str, Any]:
    """The native preprocessing options of the config's frames."""
    return image_options(config)


def require() -> None:
    """Raise :class:`~retrokit.errors.MissingExtraError` unless Stable-Baselines3 and torch are installed."""
    require_libraries("ppo", {"stable_baselines3": "Stable-Baselines3", "torch": "torch"})


def library() -> str:
    """The library and its version, for ``policy.json``."""
    import stable_baselines3

    return f"{LIBRARY} {stable_baselines3.__version__}"


def build(venv: Any, config: Mapping[str, Any]) -> Any:  # an SB3 VecEnv -> a PPO model
    """A PPO model of ``config`` on ``venv`` (its action space the task's, its observations the config's frames).

    Torch computes on one thread: a level's worker is one of several processes sharing the cores (and the
    vector env's threads step the emulators), and torch's threads spinning beside them made a 1,024-step
    PPO run on Dasher 9x slower on a loaded 2-core machine (147 s against 16 s).
    """
    import torch
    from stable_baselines3 import PPO

    torch.set_num_threads(1)

    return PPO(
        "CnnPolicy", venv, n_steps=config["horizon"], batch_size=config["minibatch"], n_epochs=config["epochs"],
        gamma=config["gamma"], gae_lambda=config["gae_lambda"], clip_range=config["clip"],
        ent_coef=config["entropy"], vf_coef=config["value_coef"], max_grad_norm=config["max_grad_norm"],
        learning_rate=config["learning_rate"], device="auto", verbose=0,
    )  # fmt: skip


def network(observation_space: Any, action_space: Any, config: Mapping[str, Any]) -> Any:  # spaces -> a torch module
    """The network of ``config`` alone: the ``ActorCriticCnnPolicy`` that :func:`build`'s ``CnnPolicy`` is.

    RLlib's PPO (:mod:`.rllib_ppo`) trains this very module, so its weights are the ones :func:`weights_of`
    writes and :func:`load_weights` reads, whichever backend trained them.
    """
    from stable_baselines3.common.policies import ActorCriticCnnPolicy

    rate = float(config["learning_rate"])
    return ActorCriticCnnPolicy(observation_space, action_space, lambda _: rate)


def weights_of(model: Any) -> bytes:
    """The model's network as a ``torch.save`` of its ``state_dict``."""
    import torch

    out = io.BytesIO()
    torch.save(model.policy.state_dict(), out)
    return out.getvalue()


def load_tensors(data: bytes, what: str) -> dict[str, Any]:
    """Tensors saved by ``torch.save``, loaded with torch's restricted unpickler (``weights_only=True``).

    Raises:
        PolicyFileError: ``data`` is not a mapping of names to tensors.
    """
    import torch

    try:
        value = torch.load(io.BytesIO(data), map_location="cpu", weights_only=True)
    except Exception as exc:  # noqa: BLE001 - anything a damaged or foreign file makes torch raise
        raise PolicyFileError(f"Expected {what} to be tensors saved by torch, but it cannot be loaded as them "
                              f"({type(exc).__name__}); save the policy again.") from None
    if not isinstance(value, dict):
        raise PolicyFileError(f"Expected {what} to hold a mapping of tensors, but it holds a {type(value).__name__}.")
    return value


def load_weights(model: Any, data: bytes, what: str) -> None:
    """Load a network's weights into ``model``: the same names and shapes only (see :func:`load_into`)."""
    load_into(model.policy, data, what)


def load_into(network: Any, data: bytes, what: str) -> dict[str, Any]:  # a torch.nn.Module
    """Load saved weights into a torch ``network``: the same names and shapes only; return them.

    Every torch-based agent's weights load through here (PPO's policy, Rainbow's network).

    Raises:
        PolicyFileError: They are not tensors, or their names or shapes are not this network's.
    """
    import torch

    state = load_tensors(data, what)
    ours = network.state_dict()
    if set(state) != set(ours) or any(
        not isinstance(state[key], torch.Tensor) or state[key].shape != ours[key].shape for key in ours
    ):
        raise PolicyFileError(
            f"Expected {what} to be the weights of this config's network ({len(ours)} tensors), but their names "
            "or shapes differ; it was saved from another network."
        )
    network.load_state_dict(state)
    return state


def observation_spec(venv: Any, config: Mapping[str, Any]) -> dict[str, Any]:
    """``policy.json``'s ``observation``: the shape, dtype and options of what the network sees."""
    space = venv.observation_space
    return {"shape": list(space.shape), "dtype": str(space.dtype), "options": observation_options(config)}


def play(env: gymnasium.Env, budget: int, seed: int, setup: LearnerSetup) -> None:
    """Play one level's monitored env until its budget is spent, learning as the paper's test runs did.

    Without learning (``setup.learn`` false), the start policy samples each action, as its zero-shot score.
    """
    from stable_baselines3.common.utils import set_random_seed
    from stable_baselines3.common.vec_env import DummyVecEnv

    from retrokit.learning.sb3task import TaskVecEnv

    # torch's, numpy's and random's (numpy takes 32 bits); the env's first reset is the runner's (the level's seed)
    set_random_seed(seed % 2**32)
    config = setup.config.values
    venv = TaskVecEnv(DummyVecEnv([lambda: env]), setup.task, config["reward_scale"])
    model = build(venv, config)
    policy = setup.start_policy()
    if policy is not None:
        load_weights(model, policy.read_weights(), f"the start policy {policy.weights_path}")
    if setup.learn:
        model.learn(total_timesteps=budget)  # the monitor ends it (BudgetSpent) at the budget's last step
        return
    obs = venv.reset()
    while True:  # the monitor ends the loop
        actions, _ = model.predict(obs, deterministic=False)
        obs, _, _, _ = venv.step(actions)


def train(run: TrainRun, *, threads: int | None = None) -> None:
    """Train one policy on the run's levels at once: ``train_envs_per_level`` envs each, every update over all."""
    import torch
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.utils import set_random_seed

    from retrokit.envs.env import make
    from retrokit.envs.vector import ThreadedVectorEnv
    from retrokit.learning.sb3task import TaskVecEnv
    from retrokit.learning.trainrun import state_bytes

    training = run.training
    config = training.config.values
    options = {**training.benchmark.env_options(), **observation_options(config)}
    scenario = options.pop("scenario", None)
    owners = [level.name for level in training.levels for _ in range(config["train_envs_per_level"])]
    fns = [partial(make, level.game, level.state, scenario, **options)
           for level in training.levels for _ in range(config["train_envs_per_level"])]
    set_random_seed(training.seed % 2**32)
    native = ThreadedVectorEnv(fns, threads).to_sb3()
    native.seed(training.seed)
    models: list[Any] = []  # the model, once made: its timesteps date each episode

    def ended(i: int, reward: float, steps: int) -> None:
        run.episode(owners[i], reward, steps, models[0].num_timesteps if models else None)

    venv = TaskVecEnv(native, run.task, config["reward_scale"], ended)
    try:
        model = build(venv, config)
        models.append(model)
        saved = run.resume_state()
        if saved is not None:
            load_weights(model, saved[0], f"the checkpoint in {run.path}")
            model.policy.optimizer.load_state_dict(load_tensors(saved[1], f"the checkpoint's state in {run.path}"))
            model.num_timesteps = run.timesteps
        elif training.init is not None:
            load_weights(model, training.init.read_weights(), f"the start policy {training.init.weights_path}")
        spec, name = observation_spec(venv, config), library()

        def save() -> None:
            run.save(model.num_timesteps, weights_of(model),
                     state_bytes(torch.save, model.policy.optimizer.state_dict()), spec, name)

        class Updates(BaseCallback):
            """After each update (when the next rollout starts): progress, and a checkpoint when due."""

            def _on_rollout_start(self) -> None:
                if self.model.num_timesteps > run.timesteps and run.updated(self.model.num_timesteps):
                    save()

            def _on_step(self) -> bool:
                return True

        left = training.timesteps - run.timesteps
        if left > 0:
            model.learn(total_timesteps=left, reset_num_timesteps=saved is None, callback=Updates())
            run.updated(model.num_timesteps)
        save()
    finally:
        venv.close()
