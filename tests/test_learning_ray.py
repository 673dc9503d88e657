"""``retrokit train --backend ray``: PPO by RLlib's env runners on a 2-node Ray cluster that loses a node mid-run,
its policy read by ``evaluate --init``, ``--resume`` on Ray, Joint Rainbow on the same cluster, and the refusals.

One child process holds one ``ray.cluster_utils`` cluster for every Ray run of the module (a Ray start and
RLlib's env runners cost seconds each): a head with no CPU (the driver, which learns) and two 1-CPU nodes, so
each of the two env runners is on its own node. The runs are the CLI's, in the child, with
``TrainRun.save`` wrapped so that the events happen at a checkpoint, never after a sleep: the joint run's
first checkpoint adds a third node and removes a node holding an env runner; the killed run's first
checkpoint raises ``KeyboardInterrupt`` (Ctrl-C), then it is resumed; it starts from the joint run's policy
(``--init``). Between them, a run asks for more runners than the cluster has CPUs, and one's runners cannot
make their env. Tiny config: what is tested is the plumbing, never how well PPO learns.
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from incli import retrokit_in_process
from learningruns import tiny_config

pytest.importorskip(
    "stable_baselines3",
    reason="needs stable-baselines3 and torch's CPU build: pip install torch --index-url "
    "https://download.pytorch.org/whl/cpu && pip install 'retrokit-rl[train]'",
)
_ray = importlib.util.find_spec("ray")  # not imported here: RLlib is the child's, this process stays light
if _ray is None or not (Path(_ray.origin).parent / "rllib").is_dir():
    pytest.skip("needs RLlib: pip install 'ray[rllib]'", allow_module_level=True)

from retrokit.learning.policy import read_policy

REPO = Path(__file__).resolve().parent.parent
pytestmark = pytest.mark.timeout(900)  # the cluster's runs, one child: 2 minutes on a quiet 2-core machine
# Episodes of at most 30 steps, under a horizon of 32: every runner's env ends one in each fragment it plays.
TINY = {"horizon": 32, "minibatch": 32, "epochs": 1, "frame_size": 36, "train_envs_per_level": 1}
LEVELS = ("Dasher-Genesis/Zone1.Act1", "Dasher-Genesis/Zone2.Act1")
TIMESTEPS = 256  # four updates of 2 runners x 32
RAINBOW_TINY = {"frame_size": 36, "minibatch": 8, "learning_starts": 64, "target_update": 32, "replay": 1000}

CLUSTER = r'''
import json, logging, os, sys
from pathlib import Path
os.environ["RAY_USAGE_STATS_ENABLED"] = "0"
import ray
from ray.cluster_utils import Cluster
import numpy as np, torch
from retrokit.cli import main
from retrokit.learning import raytrain, rllib_ppo, trainrun
from ray.rllib.core import DEFAULT_MODULE_ID

folder, common = Path(sys.argv[1]), json.loads(sys.argv[2])
cluster = Cluster(initialize_head=True, head_node_args={"num_cpus": 0, "include_dashboard": False})
nodes = [cluster.add_node(num_cpus=1), cluster.add_node(num_cpus=1)]
cluster.wait_for_nodes()
ray.init(address=cluster.address, logging_level=logging.WARNING, log_to_driver=False)
results = {"address": cluster.address, "processes": []}


def processes():
    """This process's descendants (Ray's servers, raylets, env runners) as (pid, start time)."""
    parents = {}
    for entry in os.listdir("/proc"):
        try:
            fields = open(f"/proc/{entry}/stat").read().rsplit(")", 1)[1].split()
            parents[int(entry)] = (int(fields[1]), fields[19])
        except (ValueError, OSError, IndexError):
            continue
    found, todo = [], [os.getpid()]
    while todo:
        pid = todo.pop()
        for child, (parent, start) in parents.items():
            if parent == pid:
                found.append((child, start))
                todo.append(child)
    return found


saving, events = trainrun.TrainRun.save, []


def save(self, timesteps, *args):
    saving(self, timesteps, *args)
    if self.path.name == "joint" and not events:
        results["processes"] = processes()
        cluster.add_node(num_cpus=1)  # room for the runner RLlib starts again
        cluster.wait_for_nodes()
        cluster.remove_node(nodes[0])
        events.append(timesteps)
        results["removed_at"] = timesteps
    if self.path.name == "killed" and "killed" not in results:
        results["killed"] = timesteps
        raise KeyboardInterrupt


trainrun.TrainRun.save = save
weighing, modules = rllib_ppo.weights_of, []


def weights_of(algorithm):
    found = algorithm.learner_group.foreach_learner(lambda learner: learner.module[DEFAULT_MODULE_ID])
    modules[:] = [next(iter(found)).get()]  # the driver's learner: the module object itself
    runners = algorithm.env_runner_group
    results.setdefault("runners", []).append([runners.num_healthy_remote_workers(), runners.num_remote_worker_restarts()])
    return weighing(algorithm)


rllib_ppo.weights_of = weights_of
restoring = rllib_ppo.restore


def restore(algorithm, weights, state):
    """RLlib's restore, then whether the learner's network holds the weights given, tensor for tensor."""
    import io
    restoring(algorithm, weights, state)
    now, given = (torch.load(io.BytesIO(data), weights_only=True) for data in (weighing(algorithm), weights))
    same = set(now) == set(given) and all(torch.equal(now[key], given[key]) for key in given)
    results.setdefault("restored", []).append({"state": state is not None, "same": same})


rllib_ppo.restore = restore


def run(*args):
    import contextlib, io
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(["train", *common, *args])
    return {"code": code, "stderr": err.getvalue()}


def train(out, *more):
    return run("--backend", "ray", "--ray-address", cluster.address, "--out", str(folder / out), *more)


results["joint"] = train("joint")
module = modules[0]
obs = np.random.default_rng(5).integers(0, 256, (3, 4, 36, 36), dtype=np.uint8)
with torch.no_grad():
    batch = {"obs": torch.from_numpy(obs)}
    logits = module.forward_inference(batch)["action_dist_inputs"].numpy()
    values = module.compute_values(batch).numpy()
np.savez(folder / "outputs.npz", obs=obs, logits=logits, values=values)
results["too_many"] = train("too-many", "--env-runners", "4")  # 2 CPUs: RLlib would wait without end


def no_rom_here(spec, context):
    """A runner's env on a node without the game's ROM (pickled by value: this script is the runners' __main__)."""
    raise FileNotFoundError("no ROM on this node")


making, raytrain.make_env = raytrain.make_env, no_rom_here
results["runners_fail"] = train("runners-fail")
raytrain.make_env = making
start = ("--init", str(folder / "joint"))  # the killed run starts from the joint run's policy
results["killed_run"] = train("killed", *start)
results["other_backend"] = run("--out", str(folder / "killed"), "--resume", *start)
results["resumed"] = train("killed", "--resume", *start)
# Joint Rainbow on the same cluster: RLlib's DQN on the local Rainbow's network (an iteration samples 1,000 steps)
results["rainbow"] = train("rainbow", "--agent", "rainbow", "--agent-config", sys.argv[3], "--timesteps", "64")
ray.shutdown()
cluster.shutdown()
(folder / "results.json").write_text(json.dumps(results))
'''


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("ray")


@pytest.fixture(scope="module")
def common(folder) -> list[str]:
    """The train options every run shares: a Dasher whose episodes end by 30 steps, the tiny config, 2 levels."""
    benchmark = yaml.safe_load((REPO / "retrokit" / "benchmark" / "dasher.yaml").read_text())
    benchmark["name"], benchmark["env"]["max_episode_steps"] = "dasher-short", 30
    (folder / "short.yaml").write_text(yaml.safe_dump(benchmark))
    tiny = tiny_config(folder, "ppo", TINY)
    return ["--benchmark", str(folder / "short.yaml"), "--agent-config", str(tiny), "--levels", ",".join(LEVELS),
            "--timesteps", str(TIMESTEPS), "--checkpoint-every", "0", "--no-progress"]


@pytest.fixture(scope="module")
def cluster(folder, common) -> dict:
    """The child's runs on its 2-node cluster (see the module's doc): what each returned, and Ray's processes."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
    script = folder / "cluster.py"
    script.write_text(CLUSTER)
    (folder / "rainbow-config").mkdir()
    rainbow = tiny_config(folder / "rainbow-config", "rainbow", RAINBOW_TINY)
    try:
        done = subprocess.run([sys.executable, str(script), str(folder), json.dumps(common), str(rainbow)], env=env,
                              cwd=folder, capture_output=True, text=True, timeout=840, stdin=subprocess.DEVNULL,
                              check=False)
    except subprocess.TimeoutExpired as expired:  # what the child had done by then, not only that it took long
        output = "".join(part.decode(errors="replace") if isinstance(part, bytes) else part or ""
                         for part in (expired.stdout, expired.stderr))
        pytest.fail(f"the cluster's runs took over {expired.timeout} s; they printed:\n{output[-6000:]}")
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    return json.loads((folder / "results.json").read_text())


def _episodes(out: Path) -> list[list[str]]:
    lines = (out / "curve.csv").read_text().splitlines()
    assert lines[0] == "timesteps,level,episode,steps,reward,wall"
    return [line.split(",") for line in lines[1:]]


def test_a_node_lost_mid_run_does_not_end_it(folder, cluster) -> None:
    joint = cluster["joint"]
    assert joint["code"] == 0, joint["stderr"]
    assert 0 < cluster["removed_at"] < TIMESTEPS  # the node went at the first checkpoint, with updates to go
    run = json.loads((folder / "joint" / "run.json").read_text())
    assert run["checkpoint"]["timesteps"] == TIMESTEPS
    assert run["settings"]["backend"] == "ray" and run["settings"]["env_runners"] == 2


def test_ray_training_writes_the_policy_and_every_levels_episodes(folder, cluster) -> None:
    out = folder / "joint"
    policy = read_policy(out, "ppo")
    assert policy.meta["timesteps"] == TIMESTEPS and policy.meta["library"].startswith("ray[rllib] ")
    assert policy.meta["observation"]["shape"] == [4, 36, 36] and policy.meta["observation"]["dtype"] == "uint8"
    episodes = _episodes(out)
    assert {row[1] for row in episodes} == set(LEVELS)
    assert all(0 < int(row[3]) <= 30 for row in episodes)  # the benchmark's steps, its episodes' bound kept
    run = json.loads((out / "run.json").read_text())
    assert len(episodes) == sum(run["checkpoint"]["episodes"].values())
    assert (out / "curve.png").read_bytes()[:4] == b"\x89PNG"


def test_the_ray_policy_is_the_local_ppo_network_evaluate_loads(folder, common, cluster) -> None:
    import numpy as np
    import torch
    from stable_baselines3.common.vec_env import DummyVecEnv

    from retrokit.benchmark.definition import load_benchmark
    from retrokit.envs.env import make
    from retrokit.learning import ppo
    from retrokit.learning.sb3task import TaskVecEnv
    from retrokit.learning.setup import prepare

    tiny = folder / "tiny.yaml"
    done = retrokit_in_process(folder, "evaluate", "--agent", "ppo", "--agent-config", str(tiny), "--init",
                               str(folder / "joint"), "--no-learn", "--levels", "Zone1.Act2", "--timesteps", "40",
                               "--workers", "1", "--no-progress", "--out", str(folder / "zero-shot"))
    assert done.returncode == 0, done.stderr
    # evaluate's own network (ppo.play's build and load) against RLlib's trained module, on the same frames
    benchmark = load_benchmark("dasher")
    setup = prepare("ppo", benchmark, tiny, folder / "joint", learn=False)
    options = {**benchmark.env_options(), **setup.observation}
    venv = TaskVecEnv(DummyVecEnv([lambda: make("Dasher-Genesis", "Zone1.Act2", options.pop("scenario", None),
                                                 **options)]), setup.task, 1.0)
    model = ppo.build(venv, setup.config.values)
    ppo.load_weights(model, setup.start_policy().read_weights(), "the Ray policy")
    saved = np.load(folder / "outputs.npz")
    obs = torch.from_numpy(saved["obs"])
    with torch.no_grad():
        ours = model.policy.get_distribution(obs).distribution.logits
        values = model.policy.predict_values(obs).squeeze(-1)
    theirs = torch.from_numpy(saved["logits"])
    torch.testing.assert_close(ours, theirs - torch.logsumexp(theirs, -1, keepdim=True), rtol=0, atol=1e-6)
    torch.testing.assert_close(values, torch.from_numpy(saved["values"]), rtol=0, atol=1e-6)
    venv.close()


def test_init_and_resume_on_ray_load_the_weights_and_another_backend_is_refused(folder, cluster) -> None:
    killed, resumed = cluster["killed_run"], cluster["resumed"]
    # --init loaded the joint policy's weights, the resume the checkpoint's weights and optimizer state
    assert cluster["restored"] == [{"state": False, "same": True}, {"state": True, "same": True}]
    assert killed["code"] == 130 and "add --resume" in killed["stderr"]
    other = cluster["other_backend"]
    assert other["code"] == 2 and "backend, env_runners differ" in other["stderr"], other["stderr"]
    assert resumed["code"] == 0, resumed["stderr"]
    run = json.loads((folder / "killed" / "run.json").read_text())
    assert run["checkpoint"]["timesteps"] == TIMESTEPS and read_policy(folder / "killed").meta["timesteps"] == TIMESTEPS
    timesteps = [int(row[0]) for row in _episodes(folder / "killed")]
    assert timesteps == sorted(timesteps) and timesteps[-1] > cluster["killed"]  # went on from the checkpoint


def test_joint_rainbow_trains_on_ray_and_evaluate_plays_its_policy(folder, cluster) -> None:
    """RLlib's DQN trained the Rainbow on both nodes' runners; its policy is the local Rainbow's (evaluate loads it).

    That the two networks give the same distributions is tests/test_learning_rllib_rainbow.py's.
    """
    done = cluster["rainbow"]
    assert done["code"] == 0, done["stderr"]
    out = folder / "rainbow"
    policy = read_policy(out, "rainbow")
    assert policy.meta["library"].startswith("ray[rllib] ") and policy.meta["timesteps"] >= 64
    assert policy.meta["observation"]["shape"] == [4, 36, 36]
    assert {row[1] for row in _episodes(out)} == set(LEVELS)
    run = json.loads((out / "run.json").read_text())
    assert run["settings"]["backend"] == "ray" and run["settings"]["agent"] == "rainbow"
    played = retrokit_in_process(folder, "evaluate", "--agent", "rainbow", "--agent-config",
                                 str(folder / "rainbow-config" / "tiny.yaml"), "--init", str(out), "--no-learn",
                                 "--levels", "Zone1.Act2", "--timesteps", "40", "--workers", "1", "--no-progress",
                                 "--out", str(folder / "rainbow-zero-shot"))
    assert played.returncode == 0, played.stderr
    assert json.loads((folder / "rainbow-zero-shot" / "summary.json").read_text())["complete"]


def test_more_runners_than_the_cluster_has_cpus_is_refused(folder, cluster) -> None:
    refused = cluster["too_many"]
    assert refused["code"] == 2 and "Expected a CPU for each of the 4 env runners" in refused["stderr"]
    assert "it has 2; add nodes, or use --env-runners 2." in refused["stderr"]
    assert not (folder / "too-many").exists()


def test_runners_that_cannot_make_their_env_are_one_line(folder, cluster) -> None:
    failed = cluster["runners_fail"]
    assert failed["code"] == 2 and "Expected RLlib's 2 env runners to start on the Ray cluster" in failed["stderr"]
    assert "every node needs retrokit, RLlib and the benchmark's ROMs" in failed["stderr"]
    assert len(failed["stderr"].strip().splitlines()) == 1


def test_no_ray_process_is_left_behind(cluster) -> None:
    assert len(cluster["processes"]) >= 4  # the GCS, raylets, env runners: what the run had started
    left = []
    for pid, start in cluster["processes"]:
        try:
            fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if fields[19] == start and fields[0] != "Z":
            left.append(pid)
    assert not left


@pytest.mark.parametrize(("args", "message"), [
    (("--backend", "ray", "--ray-address", "127.0.0.1:1"), "Expected a Ray cluster at 127.0.0.1:1"),
    (("--backend", "ray", "--ray-address", "nowhere"), "Expected --ray-address as HOST:PORT"),
    (("--backend", "ray", "--env-runners", "3"), "Expected --env-runners to be a multiple of the 2 level(s)"),
    (("--backend", "ray", "--env-runners", "0"), "Expected --env-runners to be a multiple"),
    (("--backend", "ray", "--env-runners", str(10**12)), "up to 4096, got 1000000000000"),
    (("--backend", "ray", "--agent", "rainbow", "--agent-config", "paper"),
     "Expected Rainbow's replay of 500,000 transitions (RLlib's, in the Ray driver) to fit in memory"),
    (("--ray-address", "127.0.0.1:1"), "Expected --ray-address and --env-runners with --backend ray only"),
    (("--backend", "ray"), "Expected room for the 2 env runners of a local Ray (about 600 MiB each"),
], ids=["unreachable", "malformed", "runners-not-a-multiple", "no-runners", "runners-huge", "rainbow-replay",
        "address-without-ray", "local-ray-out-of-memory"])
def test_bad_ray_options_are_one_line(folder, common, args, message, monkeypatch) -> None:
    """Refused before the folder is claimed, and before Ray or RLlib is imported."""
    if "--ray-address" not in args:  # a local Ray: its 2 runners must fit in memory (1 GiB here: they do not)
        monkeypatch.setattr("retrokit.envs.memory.available_memory", lambda: 1 << 30)
    base = [a for a in common if a not in ("--agent-config", str(folder / "tiny.yaml"))]
    if "--agent" not in args:
        base += ["--agent-config", str(folder / "tiny.yaml")]
    before = set(sys.modules)  # other files' tests in this worker may have imported RLlib: what the refusal adds
    done = retrokit_in_process(folder, "train", *base, *args, "--out", str(folder / "refused"))
    assert done.returncode == 2 and message in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and not (folder / "refused").exists()
    imported = set(sys.modules) - before
    assert not {name for name in imported if name.startswith(("ray.rllib", "retrokit.learning.rllib_ppo"))}
