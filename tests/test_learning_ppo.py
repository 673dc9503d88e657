"""PPO end to end at tiny budgets: evaluate (learning, --init from a train folder or its policy file, zero-shot),
train and its resume after a SIGKILL, and the refusals of changed settings.

Tiny means a 36-pixel frame (the Nature CNN's smallest input), updates of 32 timesteps and one epoch: what is
tested is the plumbing, never how well PPO learns.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from incli import retrokit_in_process
from learningruns import evaluate, evaluate_three_ways, tiny_config

pytest.importorskip(
    "stable_baselines3",
    reason="needs stable-baselines3 and torch's CPU build: pip install torch --index-url "
    "https://download.pytorch.org/whl/cpu && pip install 'retrokit-rl[train]'",
)

from retrokit.benchmark.definition import load_benchmark
from retrokit.benchmark.level import LevelDone, LevelTask, run_level
from retrokit.learning.policy import read_policy
from retrokit.learning.setup import prepare

REPO = Path(__file__).resolve().parent.parent
TINY = {"horizon": 32, "minibatch": 32, "epochs": 1, "frame_size": 36, "train_envs_per_level": 1}


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("ppo")


@pytest.fixture(scope="module")
def tiny(folder) -> Path:
    return tiny_config(folder, "ppo", TINY)


@pytest.fixture(scope="module")
def trained(folder, tiny) -> Path:
    """`retrokit train` on Dasher's three training levels: two updates of 3 x 32 timesteps."""
    out = folder / "joint"
    done = retrokit_in_process(folder, "train", "--agent-config", str(tiny), "--timesteps", "192",
                               "--checkpoint-every", "0", "--no-progress", "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert "trained ppo for 192 timesteps" in done.stdout
    return out


def test_train_writes_the_policy_the_curve_and_a_checkpoint(trained) -> None:
    policy = read_policy(trained, "ppo")
    assert policy.meta["timesteps"] == 192 and policy.meta["benchmark"] == "dasher"
    assert policy.meta["observation"]["shape"] == [4, 36, 36]
    assert policy.meta["actions"][-1] == ["B"] and policy.meta["x"] == "p1_x"
    assert len(policy.read_weights()) > 100_000
    run = json.loads((trained / "run.json").read_text())
    assert run["checkpoint"]["timesteps"] == 192
    assert run["settings"]["levels"] == [f"Dasher-Genesis/Zone{z}.Act1" for z in (1, 2, 3)]
    lines = (trained / "curve.csv").read_text().splitlines()
    assert lines[0] == "timesteps,level,episode,steps,reward,wall"
    assert len(lines) - 1 == sum(run["checkpoint"]["episodes"].values())
    assert (trained / "curve.png").read_bytes()[:4] == b"\x89PNG"
    assert not (trained / "run.lock").exists()


def _evaluate(folder: Path, out: str, *args: str) -> subprocess.CompletedProcess:
    return evaluate(folder, "ppo", 80, out, *args)


def test_evaluate_learns_from_scratch_and_from_the_trained_policy(folder, tiny, trained) -> None:
    for out, setup in evaluate_three_ways(folder, "ppo", 80, tiny, trained).items():
        assert setup["config"]["values"]["horizon"] == 32
        assert setup["paper_agent"] == {"scratch": "PPO", "from-folder": "Joint PPO", "zero-shot": None}[out]
        if setup["init"]:
            assert setup["init"]["weights_sha256"] == read_policy(trained).sha256
    # --resume refuses another config, or the same start policy played without learning (an option left out is
    # no change: it is taken from the run folder, below)
    other = folder / "tiny-other.yaml"
    other.write_text(tiny.read_text().replace("entropy: 0.01", "entropy: 0.02"))
    for args in (("--agent-config", str(other), "--init", str(trained)),
                 ("--agent-config", str(tiny), "--init", str(trained / "policy.json"), "--no-learn")):
        done = _evaluate(folder, "from-folder", *args, "--resume")
        assert done.returncode == 2 and "agent_setup differ" in done.stderr, done.stderr
    # `--out DIR --resume` alone takes the config, the start policy and --no-learn from the run folder
    for out in ("scratch", "from-folder", "zero-shot"):
        done = retrokit_in_process(folder, "evaluate", "--out", str(folder / out), "--resume", "--no-progress")
        assert done.returncode == 0, done.stderr


def test_zero_shot_never_updates_the_policy(folder, tiny, trained, monkeypatch) -> None:
    """Played in this process with PPO's update patched to fail: zero-shot finishes, learning does not."""
    from stable_baselines3 import PPO

    def no_update(self):
        raise AssertionError("PPO updated its policy")

    monkeypatch.setattr(PPO, "train", no_update)
    benchmark = load_benchmark("dasher")
    for learn in (False, True):
        setup = prepare("ppo", benchmark, tiny, trained, learn=learn)
        messages = []
        run_level(LevelTask(benchmark, benchmark.test[0], "ppo", 40, 0, False, setup), messages.append)
        assert isinstance(messages[-1], LevelDone) == (not learn), messages[-1]
        if learn:
            assert "PPO updated its policy" in messages[-1].error


@pytest.mark.parametrize(("args", "message"), [
    (("--init", "nowhere"), "Expected a saved policy at 'nowhere'"),
    (("--init", "TRAINED", "--agent-config", "paper"), "to see the observation this config makes"),
    (("--no-learn",), "Expected --init PATH with --no-learn"),
    (("--agent-config", "papr"), "Did you mean 'paper'"),
    (("--agent", "random", "--agent-config", "quick"), "Expected --agent-config with a learning agent"),
    (("--gif",), "Expected no --gif with the learning agent ppo"),
], ids=["no-policy", "other-observation", "no-learn-alone", "config-typo", "config-for-random", "gif"])
def test_bad_learning_options_are_one_line(folder, trained, args, message) -> None:
    args = tuple(str(trained) if a == "TRAINED" else a for a in args)
    done = _evaluate(folder, "refused", *args)
    assert done.returncode == 2 and message in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and not (folder / "refused" / "run.json").exists()


def test_a_killed_train_resumes_from_its_checkpoint(folder, tiny) -> None:
    out = folder / "killed"
    args = [sys.executable, "-m", "retrokit", "train", "--agent-config", str(tiny), "--timesteps", "1920",
            "--checkpoint-every", "0", "--out", str(out)]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
    first = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, cwd=folder)
    try:
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline and first.poll() is None:
            try:
                checkpoint = json.loads((out / "run.json").read_text())["checkpoint"]
            except (OSError, ValueError):
                checkpoint = None
            if checkpoint:
                break
            time.sleep(0.05)
        assert first.poll() is None, first.communicate()  # 19 updates to go: it cannot have ended meanwhile
        first.send_signal(signal.SIGKILL)
        first.wait()
    finally:
        if first.poll() is None:
            first.kill()
            first.wait()
    saved = json.loads((out / "run.json").read_text())["checkpoint"]["timesteps"]
    assert 96 <= saved < 1920
    more = [("1921" if arg == "1920" else arg) for arg in args]
    changed = subprocess.run([*more, "--resume"], check=False, capture_output=True, text=True, env=env, cwd=folder)
    assert changed.returncode == 2 and "timesteps differ" in changed.stderr
    resumed = subprocess.run([*args, "--resume"], check=False, capture_output=True, text=True, env=env, cwd=folder)
    assert resumed.returncode == 0, resumed.stderr
    progress = [line for line in resumed.stderr.splitlines() if line.startswith("train: ")]
    first_shown = int(progress[0].split()[1].split("/")[0].replace(",", ""))
    assert first_shown == saved + 96  # it went on from the checkpoint, one update further
    run = json.loads((out / "run.json").read_text())
    assert run["checkpoint"]["timesteps"] == 1920 and read_policy(out).meta["timesteps"] == 1920
    episodes = (out / "curve.csv").read_text().splitlines()[1:]
    assert len(episodes) == sum(run["checkpoint"]["episodes"].values())
