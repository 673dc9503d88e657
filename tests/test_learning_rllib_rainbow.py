"""Rainbow trained by RLlib on Ray: the config's keys on RLlib's DQN, refusals, and one tiny training on a local
2-CPU Ray whose policy the local Rainbow's network loads, with the same return distributions.

Tiny means 36-pixel frames (the Nature CNN's smallest input), minibatches of 8 and learning from 64
transitions: what is tested is the mapping and the weights, never how well Rainbow learns. One Ray and one
trained algorithm are shared by the module's tests; the Ray is shut down at its end.
"""

from __future__ import annotations

import copy
import io
import itertools
import os
import sys

import numpy as np
import pytest

pytest.importorskip("torch", reason="needs torch's CPU build and RLlib: pip install 'retrokit-rl[train,ray]'")
pytest.importorskip("tianshou", reason="needs Tianshou: pip install 'retrokit-rl[train]'")
pytest.importorskip("ray.rllib", reason="needs RLlib: pip install 'ray[rllib]'")

import retrokit.envs.memory
from retrokit.errors import AgentConfigError, InvalidArgumentError, PolicyFileError
from retrokit.learning import rainbow
from retrokit.learning import rllib_rainbow as rr
from retrokit.learning.config import load_config

pytestmark = pytest.mark.timeout(600)
TINY = {"frame_size": 36, "minibatch": 8, "learning_starts": 64, "target_update": 32, "replay": 1000}
ENV = "retrokit-test-dasher-rainbow"
STEPS = 200  # two iterations of 100 steps: learning starts in the first, the target is copied in each


def tiny() -> dict:
    return {**load_config("rainbow", "quick").values, **TINY}


@pytest.fixture
def roomy(monkeypatch):
    """A machine with room for the paper's replay: the mapping is checked apart from this one's memory."""
    monkeypatch.setattr(retrokit.envs.memory, "available_memory", lambda: None)


def test_importing_it_imports_neither_ray_nor_torch() -> None:
    """retrokit's CLI imports the learning modules without the train extra: RLlib only inside the functions."""
    import subprocess

    code = "import sys, retrokit.learning.rllib_rainbow; print([m for m in ('ray', 'torch') if m in sys.modules])"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    assert done.stdout.strip() == "[]"


def test_every_key_of_a_rainbow_config_is_mapped() -> None:
    assert list(rr.MAPPING) == list(rainbow.KEYS)


def test_the_docs_map_every_key() -> None:
    """docs/learning.md's "Rainbow on Ray" table names every key of the config."""
    from pathlib import Path

    text = (Path(__file__).parent.parent / "docs" / "learning.md").read_text()
    section = text.split("## Rainbow on Ray")[1].split("\n## ")[0]
    table = [line for line in section.splitlines() if line.startswith("| `")]
    assert [key for key in rainbow.KEYS if not any(f"`{key}`" in line.split(" | ")[0] for line in table)] == []


def test_paper_config_is_rllibs_dqn_as_the_local_rainbow(roomy) -> None:
    from ray.rllib.algorithms.dqn.dqn import calculate_rr_weights

    from retrokit.learning.rllib_rainbow_module import CONFIG, RainbowLearner, RainbowModule

    paper = load_config("rainbow").values
    dqn = rr.algorithm_config(paper, ENV, 4, 2, 7)
    assert (dqn.lr, dqn.adam_epsilon, dqn.gamma) == (0.0000625, 0.00015, 0.99)
    assert (dqn.num_atoms, dqn.v_min, dqn.v_max, dqn.n_step) == (51, -200.0, 200.0, 3)
    assert dqn.double_q and dqn.dueling and dqn.tau == 1.0 and dqn.grad_clip is None
    assert dqn.replay_buffer_config == {"type": "PrioritizedEpisodeReplayBuffer", "capacity": 500_000,
                                        "alpha": 0.5, "beta": 0.4}
    assert (dqn.train_batch_size_per_learner, dqn.target_network_update_freq) == (32, 8192)
    assert dqn.num_steps_sampled_before_learning_starts == 20_000
    assert dqn.epsilon == [(0, 0.0)] and dqn.seed == 7 and dqn.env == ENV
    assert (dqn.num_env_runners, dqn.num_envs_per_env_runner, dqn.rollout_fragment_length) == (4, 2, 4)
    assert dqn.learner_class is RainbowLearner
    spec = dqn.get_rl_module_spec()
    assert spec.module_class is RainbowModule and spec.model_config[CONFIG] == dict(paper)
    # One update per update_every steps: each of the 8 envs steps 4 times an iteration, then 8 updates.
    assert calculate_rr_weights(dqn) == [1, 8]


@pytest.mark.parametrize(("runners", "envs", "n_step", "fragment", "updates"), [
    (0, 1, 3, 4, 1), (1, 1, 3, 4, 1), (3, 4, 3, 4, 12), (2, 1, 6, 8, 4), (0, 8, 1, 4, 8),
], ids=["driver-only", "one-runner", "twelve-envs", "n-step-over-update-every", "driver-eight-envs"])
def test_one_update_per_update_every_steps(roomy, runners, envs, n_step, fragment, updates) -> None:
    """RLlib's round-robin weights give one update per update_every (4) steps gathered, whatever the envs."""
    from ray.rllib.algorithms.dqn.dqn import calculate_rr_weights

    dqn = rr.algorithm_config({**tiny(), "n_step": n_step}, ENV, runners, envs, 0)
    assert dqn.rollout_fragment_length == fragment
    assert calculate_rr_weights(dqn) == [1, updates]
    assert updates * 4 == fragment * envs * max(runners, 1)


def test_a_replay_that_does_not_fit_is_refused(monkeypatch) -> None:
    """RLlib keeps the stacked frames of each step: the paper's 0.5M transitions take 14 GB there."""
    paper = load_config("rainbow").values
    assert rr.replay_bytes(paper, 500_000) == 500_000 * (4 * 84 * 84 + rr.RLLIB_TRANSITION_EXTRA_BYTES)
    monkeypatch.setattr(retrokit.envs.memory, "available_memory", lambda: 8 << 30)
    with pytest.raises(InvalidArgumentError) as caught:
        rr.algorithm_config(paper, ENV, 2, 1, 0)
    message = str(caught.value)
    assert "500,000 transitions (RLlib's, in the Ray driver)" in message and "13.5 GiB" in message
    assert "8.0 GiB are available" in message and "\n" not in message
    rr.algorithm_config(load_config("rainbow", "quick").values, ENV, 2, 1, 0)  # 100,000: 2.7 GiB fits


@pytest.mark.parametrize(("config", "runners", "envs", "seed", "error", "message"), [
    ("ppo", 1, 1, 0, AgentConfigError, "Expected only keys of a rainbow config"),
    ("rainbow", -1, 1, 0, InvalidArgumentError, "got -1, 1, 0"),
    ("rainbow", 2, 0, 0, InvalidArgumentError, "got 2, 0, 0"),
    ("rainbow", "2", 1, 0, InvalidArgumentError, "got '2', 1, 0"),
    ("rainbow", 2, True, 0, InvalidArgumentError, "got 2, True, 0"),
    ("rainbow", 2, 1, -5, InvalidArgumentError, "got 2, 1, -5"),
], ids=["ppo-config", "negative-runners", "no-envs", "runners-text", "envs-bool", "negative-seed"])
def test_wrong_arguments_are_one_line(roomy, config, runners, envs, seed, error, message) -> None:
    with pytest.raises(error) as caught:
        rr.algorithm_config(load_config(config).values, ENV, runners, envs, seed)
    assert message in str(caught.value) and "\n" not in str(caught.value)


@pytest.mark.parametrize("change", [{}, {"noisy": False}, {"dueling": False}, {"noisy": False, "dueling": False}],
                         ids=["rainbow", "plain-heads", "one-stream", "plain-one-stream"])
def test_the_module_is_the_local_network(change) -> None:
    """Built alone (no Ray), the module's network is the local Rainbow's, key for key, and gives its
    distributions, whatever the heads; its logits are the ones RLlib's loss takes."""
    import gymnasium
    import torch
    from ray.rllib.core.columns import Columns

    from retrokit.learning.rllib_rainbow_module import CONFIG, RainbowModule

    config = {**tiny(), **change}
    space = gymnasium.spaces.Box(0, 255, (4, 36, 36), np.uint8)
    module = RainbowModule(observation_space=space, action_space=gymnasium.spaces.Discrete(7), inference_only=False,
                           model_config={CONFIG: config})
    local = rainbow.build(config, space.shape, 7)
    weights = io.BytesIO()
    torch.save(module.network.state_dict(), weights)
    rainbow.load_weights(local, weights.getvalue(), "the module's weights")
    obs = np.random.default_rng(5).integers(0, 256, (3, *space.shape), dtype=np.uint8)
    with torch.no_grad():
        out = module.compute_q_values({Columns.OBS: torch.as_tensor(obs)})
        ours = local.network(obs)[0].numpy()
    np.testing.assert_allclose(out["qf_probs"].numpy(), ours, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(torch.softmax(out["qf_logits"], -1).numpy(), ours, rtol=1e-5, atol=1e-6)
    atoms = np.linspace(config["v_min"], config["v_max"], config["atoms"])
    np.testing.assert_allclose(out["qf_preds"].numpy(), (ours * atoms).sum(-1), rtol=1e-4, atol=1e-5)


def test_an_env_runner_draws_new_noise_every_update_every_steps() -> None:
    """Acting (RLlib's exploration pass), the module draws new noise every ``update_every`` steps, before learning
    starts too, as the local Rainbow does: between two draws it acts on one noise."""
    import gymnasium
    import torch
    from ray.rllib.core.columns import Columns
    from tianshou.utils.net.discrete import NoisyLinear

    from retrokit.learning.rllib_rainbow_module import CONFIG, RainbowModule

    config = tiny()
    space = gymnasium.spaces.Box(0, 255, (4, 36, 36), np.uint8)
    module = RainbowModule(observation_space=space, action_space=gymnasium.spaces.Discrete(7), inference_only=True,
                           model_config={CONFIG: config})
    layer = next(m for m in module.network.modules() if isinstance(m, NoisyLinear))
    batch = {Columns.OBS: torch.zeros((1, *space.shape), dtype=torch.uint8)}
    noises = []
    with torch.no_grad():
        for t in range(2 * config["update_every"]):
            noises.append(layer.eps_p.clone())
            module.forward_exploration(batch, t=t)
    changed = [not torch.equal(a, b) for a, b in itertools.pairwise(noises)]
    every = config["update_every"]
    assert changed == [(i + 1) % every == 0 for i in range(len(changed))]


@pytest.mark.parametrize(("change", "message"), [
    ({"v_min": 300.0}, "v_min (300) must be below v_max (200)"),
    ({"atoms": 1}, "atoms in the rainbow config"),
    ({"replay": 1e30}, "replay in the rainbow config"),
], ids=["empty-support", "one-atom", "huge-replay"])
def test_a_wrong_value_is_refused_as_the_loader_refuses_it(roomy, change, message) -> None:
    with pytest.raises(AgentConfigError) as caught:
        rr.algorithm_config({**load_config("rainbow").values, **change}, ENV, 1, 1, 0)
    assert message in str(caught.value) and "\n" not in str(caught.value)


# --- one tiny training on a local 2-CPU Ray ------------------------------------------------------------------


def dasher_env(config: dict):
    """A Dasher level's env as ``retrokit train`` makes it: the benchmark's rules, the config's frames."""
    from retrokit.benchmark.definition import load_benchmark
    from retrokit.envs.env import make
    from retrokit.learning.task import learning_task

    benchmark = load_benchmark("dasher")
    options = {**benchmark.env_options(), **rainbow.observation_options(config)}
    scenario = options.pop("scenario", None)
    env = make("Dasher-Genesis", "Zone1.Act1", scenario, **options)
    return rainbow.TaskEnv(env, learning_task(benchmark), config["reward_scale"])


@pytest.fixture(scope="module")
def local_ray():
    import ray
    from ray import cloudpickle
    from ray.tune.registry import register_env

    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    # "local": a new Ray of our own, even where another one runs on this machine (ray.init would join it)
    ray.init(address="local", num_cpus=2, include_dashboard=False, log_to_driver=False, logging_level="ERROR")
    # The env runner (a Ray actor) cannot import this test module: the env's maker goes to it by value.
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    config = tiny()
    register_env(ENV, lambda _: dasher_env(config))
    try:
        yield config
    finally:
        ray.shutdown()


@pytest.fixture(scope="module")
def trained(local_ray):
    """An algorithm with one env runner (a Ray actor) trained for STEPS timesteps, and its results."""
    algorithm = rr.algorithm_config(local_ray, ENV, 1, 1, 0).reporting(min_sample_timesteps_per_iteration=100)
    algorithm = algorithm.build_algo()
    try:
        results = [algorithm.train() for _ in range(STEPS // 100)]
        yield algorithm, results
    finally:
        algorithm.stop()


@pytest.fixture(scope="module")
def observation(local_ray):
    env = dasher_env(local_ray)
    try:
        obs, _ = env.reset(seed=3)
        for _ in range(30):
            obs, *_ = env.step(1)  # right: a frame with the level moving, not the first one
        return obs[None]
    finally:
        env.close()


def rllib_distributions(algorithm, obs: np.ndarray, *, means: bool = False) -> np.ndarray:
    """The learner's module's return distributions for ``obs`` (noise off with ``means``)."""
    import torch
    from ray.rllib.core.columns import Columns

    def probabilities(learner) -> np.ndarray:
        module = rr._module(learner)
        network = copy.deepcopy(module.network)
        if means:
            no_noise(network)
        with torch.no_grad():
            return module._qf_forward_helper({Columns.OBS: torch.as_tensor(obs)}, network, None)["qf_probs"].numpy()

    from retrokit.learning.raytrain import on_learners

    return on_learners(algorithm, probabilities)


def no_noise(network) -> None:
    from tianshou.utils.net.discrete import NoisyLinear

    for layer in network.modules():
        if isinstance(layer, NoisyLinear):
            layer.eps_p.data.zero_()
            layer.eps_q.data.zero_()


def local_distributions(config: dict, weights: bytes, obs: np.ndarray, *, means: bool = False) -> np.ndarray:
    """The local Rainbow's network, loaded with ``weights``, on ``obs``."""
    import torch

    learner = rainbow.build(config, obs.shape[1:], 7)
    rainbow.load_weights(learner, weights, "the Ray run's weights")
    if means:
        no_noise(learner.network)
    with torch.no_grad():
        return learner.network(obs)[0].numpy()


def test_rllib_trains_rainbow_on_dasher(trained) -> None:
    _, results = trained
    last = results[-1]
    assert last["env_runners"]["num_env_steps_sampled_lifetime"] == STEPS
    learner = last["learners"]["default_policy"]
    # A minibatch of 8 at step 64 (learning_starts) and every 4 steps after it; the target copied every 32.
    assert learner["num_module_steps_trained_lifetime"] == 8 * ((STEPS - 64) // 4 + 1)
    assert learner["num_target_updates"] == (STEPS - 64) // 32 + 1
    assert np.isfinite(learner["qf_loss"])


def test_the_local_network_gives_rllibs_distributions(trained, local_ray, observation, tmp_path) -> None:
    """weights_of's bytes, saved as a policy and read back as evaluate --init reads them, load into the local
    Rainbow's network, which then gives the RLlib module's return distributions: with the noise the run last
    drew, and with the noise off (the means)."""
    from retrokit.learning.policy import read_policy, write_policy

    algorithm, _ = trained
    weights = rr.weights_of(algorithm)
    meta = {"agent": "rainbow", "library": "ray[rllib]", "config": {"agent": "rainbow", "values": local_ray},
            "actions": [["RIGHT"]], "x": None, "benchmark": "dasher", "timesteps": STEPS,
            "observation": {"shape": list(observation.shape[1:]), "dtype": "uint8", "options": {}}}
    write_policy(tmp_path, meta, weights)
    read = read_policy(tmp_path, "rainbow").read_weights()
    assert read == weights
    for means in (False, True):
        ours = local_distributions(local_ray, read, observation, means=means)
        theirs = rllib_distributions(algorithm, observation, means=means)
        assert ours.shape == (1, 7, 51)
        np.testing.assert_allclose(ours, theirs, rtol=1e-5, atol=1e-6)
    noisy, mean = (local_distributions(local_ray, read, observation, means=m) for m in (False, True))
    assert not np.allclose(noisy, mean), "the noisy layers' noise should change the distributions"


def test_the_env_runner_acts_on_the_learners_network(trained, local_ray, observation) -> None:
    """The runner's module (synced after the last update, noise included) is the learner's network."""
    import torch
    from ray.rllib.core.columns import Columns

    algorithm, _ = trained

    def probabilities(runner) -> np.ndarray:
        with torch.no_grad():
            return runner.module.compute_q_values({Columns.OBS: torch.as_tensor(observation)})["qf_probs"].numpy()

    (acting,) = algorithm.env_runner_group.foreach_env_runner(probabilities, local_env_runner=False)
    np.testing.assert_allclose(acting, rllib_distributions(algorithm, observation), rtol=1e-5, atol=1e-6)


def test_state_round_trip_restores_the_learner(trained, local_ray, observation) -> None:
    """weights_of and state_of restored into a new algorithm (its envs in the driver) give the same
    distributions and the same Adam state; damaged or foreign bytes are one PolicyFileError."""
    import torch

    from retrokit.learning.ppo import load_tensors

    algorithm, _ = trained
    weights, state = rr.weights_of(algorithm), rr.state_of(algorithm)
    saved = torch.load(io.BytesIO(state), weights_only=True)
    assert saved["state"] and saved["param_groups"][0]["eps"] == 0.00015
    fresh = rr.algorithm_config(local_ray, ENV, 0, 1, 1).reporting(min_sample_timesteps_per_iteration=100).build_algo()
    try:
        assert not np.allclose(rllib_distributions(fresh, observation), rllib_distributions(algorithm, observation))
        rr.restore(fresh, weights, state)
        np.testing.assert_allclose(rllib_distributions(fresh, observation), rllib_distributions(algorithm, observation),
                                   rtol=1e-6, atol=1e-7)
        again = load_tensors(rr.state_of(fresh), "the restored state")
        for index, moments in saved["state"].items():
            for name, value in moments.items():
                assert torch.equal(again["state"][index][name], value), name
        assert rr.weights_of(fresh) == weights
        # The runner in the driver acts on the restored network.
        from ray.rllib.core.columns import Columns

        with torch.no_grad():
            acting = fresh.env_runner.module.compute_q_values({Columns.OBS: torch.as_tensor(observation)})
        np.testing.assert_allclose(acting["qf_probs"].numpy(), rllib_distributions(algorithm, observation),
                                   rtol=1e-6, atol=1e-7)
        # A resumed run refills its replay, then its Adam goes on from the saved steps: 10 updates from step 64.
        fresh.train()
        steps = {int(moments["step"]) for moments in load_tensors(rr.state_of(fresh), "s")["state"].values()}
        assert steps == {int(moments["step"]) + 10 for moments in saved["state"].values()}
        rr.restore(fresh, weights, None)  # --init: the weights alone

        other = rainbow.build({**local_ray, "atoms": 11}, observation.shape[1:], 7)
        refused = {"damaged": (weights[:100], None), "other-network": (rainbow.weights_of(other), None),
                   "foreign-state": (weights, weights)}
        for name, (data, extra) in refused.items():
            with pytest.raises(PolicyFileError) as caught:
                rr.restore(fresh, data, extra)
            assert "\n" not in str(caught.value), name
    finally:
        fresh.stop()
