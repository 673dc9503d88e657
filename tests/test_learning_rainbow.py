"""Rainbow: its configs against Hessel et al.'s table and the paper's changes, its network and replay, and end to
end at tiny budgets: evaluate (learning, --init from a train folder, zero-shot), train and its resume.

Tiny means 36-pixel frames (the Nature CNN's smallest input), minibatches of 8 and learning from 16 transitions:
what is tested is the plumbing and the settings, never how well Rainbow learns.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from incli import retrokit_in_process
from learningruns import evaluate_three_ways, tiny_config

from retrokit.errors import AgentConfigError
from retrokit.learning.config import CONFIG_DIR, load_config

#: Hessel et al. (2018), Table 1 and the DQN settings they keep, in agent steps: the benchmark's frame skip is 4,
#: so their 32K frames between target updates are 8,192 steps and their 80K frames before learning 20,000.
HESSEL = {
    "learning_rate": 0.0000625, "adam_epsilon": 0.00015, "gamma": 0.99, "atoms": 51, "n_step": 3,
    "noisy": True, "noisy_sigma0": 0.5, "dueling": True, "priority_alpha": 0.5,
    "priority_beta": 0.4,  # its initial value: the paper keeps it there (no schedules)
    "minibatch": 32, "target_update": 32_768 // 4, "learning_starts": 80_000 // 4, "update_every": 4,
    "frame_size": 84, "frame_stack": 4, "grayscale": True, "network": "nature_cnn",
}  # fmt: skip
#: "Gotta Learn Fast"'s changes: V_max 200 (V_min its mirror, as the paper's code has it), a replay of 0.5M,
#: and the max-x reward unscaled.
PAPER_CHANGES = {"v_min": -200.0, "v_max": 200.0, "replay": 500_000, "reward_scale": 1.0}
#: Each evaluation's worker imports torch and Tianshou (tens of CPU-seconds on a shared 2-core machine), and
#: the Ray test starts a Ray: more than the suite's 300 s on a busy machine, never a hang.
pytestmark = pytest.mark.timeout(900)
TINY = {"frame_size": 36, "minibatch": 8, "learning_starts": 16, "target_update": 16, "replay": 1000, "train_envs": 2}


def test_paper_config_is_hessels_with_the_papers_changes() -> None:
    values = load_config("rainbow").values
    assert load_config("rainbow").name == "paper"
    assert {key: values[key] for key in HESSEL} == HESSEL
    assert {key: values[key] for key in PAPER_CHANGES} == PAPER_CHANGES


def test_quick_config_says_why_it_changes_each_key() -> None:
    """Every key quick.yaml changes from paper.yaml is named in the comment above it (or above its group)."""
    paper, quick = load_config("rainbow", "paper").values, load_config("rainbow", "quick").values
    changed = [key for key in paper if paper[key] != quick[key]]
    assert changed, "quick.yaml should differ from paper.yaml"
    lines = (CONFIG_DIR / "rainbow" / "quick.yaml").read_text().splitlines()
    for key in changed:
        at = next(i for i, line in enumerate(lines) if line.startswith(f"{key}:"))
        comments = []
        for line in reversed(lines[:at]):
            if line.split(":")[0] in changed and not comments:
                continue  # keys changed together share the comment above them
            if not line.startswith("#"):
                break
            comments.append(line)
        words = key.replace("_", " ")
        assert any(key in c or words in c.lower() for c in comments), f"quick.yaml changes {key} without a comment"


@pytest.mark.parametrize(("change", "message"), [
    ({"v_min": 300.0}, "v_min (300) must be below v_max (200)"),
    ({"atoms": 1}, "atoms in the rainbow config"),
    ({"noisy": "yes"}, "must be bool"),
    ({"replay_size": 10}, "Did you mean 'replay'"),
], ids=["empty-support", "one-atom", "noisy-not-bool", "typo"])
def test_a_wrong_config_is_one_line(tmp_path, change, message) -> None:
    values = {**load_config("rainbow").values, **change}
    if "replay_size" in change:
        del values["replay"]
    path = tmp_path / "mine.yaml"
    path.write_text(yaml.safe_dump(values))
    with pytest.raises(AgentConfigError) as caught:
        load_config("rainbow", path)
    assert message in str(caught.value) and "\n" not in str(caught.value)


# --- with Tianshou and torch ---------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def tianshou():
    return pytest.importorskip(
        "tianshou",
        reason="needs Tianshou and torch's CPU build: pip install torch --index-url "
        "https://download.pytorch.org/whl/cpu && pip install 'retrokit-rl[train]'",
    )


def test_network_replay_and_updates_are_the_papers(tianshou) -> None:
    import torch
    from tianshou.utils.net.discrete import NoisyLinear

    from retrokit.learning.rainbow import build, replay, replay_bytes

    config = load_config("rainbow").values
    learner = build(config, (4, 84, 84), 7)
    convs = [m for m in learner.network.modules() if isinstance(m, torch.nn.Conv2d)]
    assert [(c.in_channels, c.out_channels, c.kernel_size[0], c.stride[0]) for c in convs] == [
        (4, 32, 8, 4), (64 // 2, 64, 4, 2), (64, 64, 3, 1)]  # Mnih et al.'s CNN
    noisy = [m for m in learner.network.modules() if isinstance(m, NoisyLinear)]
    # dueling: an advantage head (7 actions x 51 atoms) and a value head (51 atoms), each 512 noisy units wide
    assert sorted((m.in_features, m.out_features) for m in noisy) == sorted(
        [(3136, 512), (512, 7 * 51), (3136, 512), (512, 51)])
    assert {m.sigma for m in noisy} == {0.5}
    # the noisy layers are computed factorized, and stay noisy while acting (eval mode): the library's formula
    layer, x = noisy[0], torch.randn(3, 3136)
    with torch.no_grad():
        expected = x @ (layer.mu_W + layer.sigma_W * layer.eps_q.ger(layer.eps_p)).T + layer.mu_bias + layer.sigma_bias * layer.eps_q
        for mode in (True, False):
            learner.network.train(mode)
            assert torch.allclose(layer(x), expected, atol=1e-4)
        assert not torch.allclose(expected, x @ layer.mu_W.T + layer.mu_bias, atol=1e-4)
    support = learner.policy.support
    assert len(support) == 51 and support[0] == -200 and support[-1] == 200
    algorithm = learner.algorithm
    assert algorithm.n_step == 3 and algorithm.gamma == 0.99
    assert algorithm.target_update_freq == 8192 // 4  # Tianshou counts updates: one per 4 steps
    adam = algorithm.optim._optim  # the torch optimizer Tianshou wraps
    assert isinstance(adam, torch.optim.Adam)
    assert adam.defaults["lr"] == 0.0000625 and adam.defaults["eps"] == 0.00015
    buffer = replay({**config, "replay": 64}, 1)
    assert buffer.maxsize == 64 and buffer.stack_num == 4
    assert buffer.options["alpha"] == 0.5 and buffer.options["beta"] == 0.4
    # the paper's replay holds 500,000 frames of 84 x 84 bytes: 3.5 GB, once each (not 4 stacked, nor next obs)
    assert buffer.options["ignore_obs_next"] and buffer.options["save_only_last_obs"]
    assert 3.5e9 < replay_bytes(config, 500_000) < 3.6e9


def test_a_replay_that_would_not_fit_is_refused_before_play(tianshou, monkeypatch) -> None:
    import retrokit.envs.memory
    from retrokit.errors import InvalidArgumentError
    from retrokit.learning.rainbow import replay

    monkeypatch.setattr(retrokit.envs.memory, "available_memory", lambda: 2 << 30)
    with pytest.raises(InvalidArgumentError, match=r"replay of 500,000 transitions .* 3.3 GiB, and 2.0 GiB"):
        replay(load_config("rainbow").values, 1)


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("rainbow")


@pytest.fixture(scope="module")
def tiny(tianshou, folder) -> Path:
    return tiny_config(folder, "rainbow", TINY)


@pytest.fixture(scope="module")
def trained(folder, tiny) -> Path:
    """`retrokit train --agent rainbow` on Dasher's training levels: 2 envs, each drawing a level per episode."""
    out = folder / "joint"
    done = retrokit_in_process(folder, "train", "--agent", "rainbow", "--agent-config", str(tiny),
                               "--timesteps", "64", "--checkpoint-every", "0", "--no-progress", "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert "trained rainbow for 64 timesteps" in done.stdout
    return out


def test_train_writes_a_policy_evaluate_reads(trained) -> None:
    from retrokit.learning.policy import read_policy

    policy = read_policy(trained, "rainbow")
    assert policy.meta["timesteps"] == 64 and policy.meta["library"].startswith("tianshou ")
    assert policy.meta["observation"]["shape"] == [4, 36, 36] and policy.meta["observation"]["dtype"] == "uint8"
    assert policy.meta["actions"][-1] == ["B"] and policy.meta["x"] == "p1_x"
    run = json.loads((trained / "run.json").read_text())
    assert run["checkpoint"]["timesteps"] == 64 and set(run["checkpoint"]) >= {"weights", "state"}
    with pytest.raises(Exception, match="rainbow|ppo"):
        read_policy(trained, "ppo")  # another agent's policy is refused


def test_an_interrupted_train_resumes_from_its_checkpoint(folder, tiny, monkeypatch) -> None:
    """Interrupted after its checkpoint at 40 timesteps (collections of 2 envs x 4 steps), it goes on from there."""
    from retrokit.learning.trainrun import TrainRun

    out = folder / "resumed"
    args = ("train", "--agent", "rainbow", "--agent-config", str(tiny), "--timesteps", "96", "--checkpoint-every",
            "0", "--no-progress", "--out", str(out))
    seen: list[int] = []
    interrupted: list[int] = []
    updated = TrainRun.updated

    def interrupt_at_48(self, timesteps):
        seen.append(timesteps)
        if timesteps == 48 and not interrupted:
            interrupted.append(timesteps)
            raise KeyboardInterrupt
        return updated(self, timesteps)

    monkeypatch.setattr(TrainRun, "updated", interrupt_at_48)
    first = retrokit_in_process(folder, *args)
    assert first.returncode == 130 and "add --resume" in first.stderr, first.stderr
    assert json.loads((out / "run.json").read_text())["checkpoint"]["timesteps"] == 40
    seen.clear()
    done = retrokit_in_process(folder, *args, "--resume")
    assert done.returncode == 0, done.stderr
    assert seen[0] == 48  # the first collection after the checkpoint
    assert json.loads((out / "run.json").read_text())["checkpoint"]["timesteps"] == 96


def test_evaluate_learns_from_scratch_and_from_the_trained_policy(folder, tiny, trained) -> None:
    from retrokit.learning.policy import read_policy

    for out, setup in evaluate_three_ways(folder, "rainbow", 40, tiny, trained).items():
        assert setup["config"]["values"]["minibatch"] == 8
        assert setup["paper_agent"] == {"scratch": "Rainbow", "from-folder": "Joint Rainbow", "zero-shot": None}[out]
        if setup["init"]:
            assert setup["init"]["weights_sha256"] == read_policy(trained).sha256


def test_learning_updates_during_the_budget_and_zero_shot_never(folder, tiny, trained, monkeypatch) -> None:
    """Played in this process, updates counted: one per 4 steps once 16 transitions are in; none zero-shot.

    Between updates (before learning starts, and zero-shot) the noisy layers get new noise as often.
    """
    from tianshou.algorithm.modelfree.rainbow import RainbowDQN

    from retrokit.benchmark.definition import load_benchmark
    from retrokit.benchmark.level import LevelDone, LevelTask, run_level
    from retrokit.learning import rainbow
    from retrokit.learning.setup import prepare

    updates, draws = [], []
    update, draw = RainbowDQN.update, rainbow.draw_noise
    monkeypatch.setattr(RainbowDQN, "update", lambda self, **kw: updates.append(1) or update(self, **kw))
    monkeypatch.setattr(rainbow, "draw_noise", lambda network: draws.append(1) or draw(network))
    benchmark = load_benchmark("dasher")
    for learn in (True, False):
        updates.clear()
        draws.clear()
        setup = prepare("rainbow", benchmark, tiny, trained, learn=learn)
        messages = []
        run_level(LevelTask(benchmark, benchmark.test[0], "rainbow", 40, 0, False, setup), messages.append)
        assert isinstance(messages[-1], LevelDone), messages[-1]
        # 40 steps in collections of 4: an update after each that ends at 16, 20, ..., 40 (the 41st step ends it)
        assert len(updates) == (7 if learn else 0)
        # new noise after every collection of 4: the update's, else a draw of its own (before learning starts too)
        assert len(draws) == (3 if learn else 10)


def test_a_start_policy_of_another_network_fails_its_level_in_one_line(folder, tiny, trained) -> None:
    """Weights of 51 atoms into a config of 21: refused by names and shapes, before any step."""
    from retrokit.benchmark.definition import load_benchmark
    from retrokit.benchmark.level import LevelFailed, LevelTask, run_level
    from retrokit.learning.setup import prepare

    other = folder / "atoms21.yaml"
    other.write_text(yaml.safe_dump({**yaml.safe_load(tiny.read_text()), "atoms": 21}))
    benchmark = load_benchmark("dasher")
    messages = []
    setup = prepare("rainbow", benchmark, other, trained)
    run_level(LevelTask(benchmark, benchmark.test[0], "rainbow", 40, 0, False, setup), messages.append)
    assert isinstance(messages[-1], LevelFailed) and messages[-1].timesteps == 0
    assert "names or shapes differ" in messages[-1].error and "\n" not in messages[-1].error


def test_evaluate_learns_on_a_local_ray(folder, tiny) -> None:
    """`--backend ray`: the level is a Ray task on a local 1-CPU Ray, and Rainbow learns inside it as locally."""
    pytest.importorskip("ray", reason="needs Ray: pip install 'retrokit-rl[ray]'")
    from learningruns import evaluate

    done = evaluate(folder, "rainbow", 40, "on-ray", "--agent-config", str(tiny), "--backend", "ray")
    assert done.returncode == 0, done.stderr
    run = json.loads((folder / "on-ray" / "run.json").read_text())
    assert run["finished"]["Dasher-Genesis/Zone1.Act2"]["timesteps"] == 40
    assert run["settings"]["agent_setup"]["learn"] is True
