"""``retrokit evaluate --backend ray`` on a local Ray with 2 CPUs gives the local backend's result."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from retrokit.cli import main

# 200 timesteps: JERK (seed 3) ends 10 episodes, its first on each level under 100 steps.
ARGS = ["evaluate", "--benchmark", "dasher", "--timesteps", "200", "--seed", "3", "--no-progress"]

# JERK on every level but Zone1.Act1, where the agent sleeps: one Ray run (Ray's start takes most of its time)
# shows both that Ray gives the local backend's summary and that it stops a stalled level and keeps the others.
JERK_BUT_SLEEPS = (
    "import time\n"
    "from retrokit.benchmark.jerk import jerk\n"
    "def sleeps_on_zone1(env, budget, seed):\n"
    "    if env.unwrapped.state_name == 'Zone1.Act1':\n"
    "        time.sleep(10**6)\n"
    "    jerk(env, budget, seed)\n"
)


def test_ray_gives_the_local_summary_and_stops_a_stalled_level_keeping_the_others(tmp_path) -> None:
    agents = tmp_path / "my_agents.py"
    agents.write_text(JERK_BUT_SLEEPS)
    args = [*ARGS, "--levels", "Zone1.Act1,Zone2.Act2,Zone3.Act2", "--agent", f"{agents}:sleeps_on_zone1",
            "--stall-timeout", "5"]
    # Ray runs in a child, as a user runs it: importing Ray here would leave this test process a few hundred
    # MB larger, and the memory limits other tests check in their own children start from that size. The
    # local run plays meanwhile: most of the child's time is Ray starting, which waits more than it computes.
    # Without --ray-address the run starts a Ray of its own, whatever cluster this machine knows of (ray.init()
    # alone would join $RAY_ADDRESS, or the last cluster started here, e.g. another test's).
    elsewhere = {**os.environ, "RAY_ADDRESS": "127.0.0.1:1"}
    with subprocess.Popen([sys.executable, "-m", "retrokit", *args, "--workers", "2", "--backend", "ray",
                           "--out", str(tmp_path / "ray")], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          stdin=subprocess.DEVNULL, text=True, env=elsewhere) as child:
        try:
            assert main([*args, "--workers", "1", "--out", str(tmp_path / "local")]) == 2
            _, stderr = child.communicate(timeout=240)
        finally:
            child.kill()
    assert child.returncode == 2, stderr
    assert "Level Dasher-Genesis/Zone1.Act1 stalled and was stopped after 5 s" in stderr
    summary = json.loads((tmp_path / "ray" / "summary.json").read_text())
    assert list(summary["levels"]) == ["Dasher-Genesis/Zone2.Act2", "Dasher-Genesis/Zone3.Act2"]
    local, ray = ((tmp_path / name / "summary.json").read_bytes() for name in ("local", "ray"))
    assert local == ray
    streamed = (tmp_path / "ray" / "episodes.jsonl").read_text().splitlines()
    assert len(streamed) == len((tmp_path / "local" / "episodes.jsonl").read_text().splitlines()) > 2


def test_without_ray_the_error_says_how_to_install_it(tmp_path, monkeypatch, capsys) -> None:
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray now raises ImportError
    args = [*ARGS, "--levels", "Zone2.Act2", "--agent", "jerk", "--backend", "ray", "--out", str(tmp_path / "run")]
    assert main(args) == 2
    assert "pip install 'retrokit-rl[ray]'" in capsys.readouterr().err


LOSE_A_NODE = '''
import json, logging, os, sys, threading, time
from pathlib import Path
os.environ["RAY_USAGE_STATS_ENABLED"] = "0"
import ray
from ray.cluster_utils import Cluster
from retrokit.cli import main

out, args = Path(sys.argv[1]), sys.argv[2:]
marks = Path(os.environ["MARKS"])
cluster = Cluster(initialize_head=True, head_node_args={"num_cpus": 1, "include_dashboard": False})
node = cluster.add_node(num_cpus=1)
cluster.wait_for_nodes()
ray.init(address=cluster.address, logging_level=logging.WARNING, log_to_driver=False)
(marks / "doomed.tmp").write_text(node.node_id)
os.replace(marks / "doomed.tmp", marks / "doomed")  # the agent holds its level on this node (see MARKING_JERK)

def lose_the_node():
    """Once the level playing on the second node has logged an episode, remove that node."""
    while True:
        found = [json.loads(p.read_text()) for p in marks.glob("*.node")]
        there = [m["level"] for m in found if m["node"] == node.node_id]
        log = out / "episodes.jsonl"
        if there and log.exists() and any(json.loads(line)["level"] == there[0] for line in log.read_text().splitlines()):
            cluster.remove_node(node)
            print("removed the node of", there[0], flush=True)
            return
        time.sleep(0.05)

threading.Thread(target=lose_the_node, daemon=True).start()
code = main(["evaluate", *args, "--backend", "ray", "--out", str(out)])
ray.shutdown()
cluster.shutdown()
sys.exit(code)
'''

MARKING_JERK = '''
import json, os, pathlib, time
import gymnasium
from retrokit.benchmark.jerk import jerk


class HeldAfterItsFirstEpisode(gymnasium.Wrapper):
    """The env of the level on the node the test removes: it waits there, after its first episode, to be lost.

    So the node is lost while its level plays however fast or slow the machine is, and the level's budget
    can be small. Removing the node ends this process; if that never comes, the level fails, saying why.
    """

    def __init__(self, env):
        super().__init__(env)
        self.resets = 0

    def reset(self, **kwargs):
        self.resets += 1
        if self.resets == 2:
            deadline = time.monotonic() + 300
            while time.monotonic() < deadline:
                time.sleep(0.05)
            raise RuntimeError("the test did not remove this Ray node within 300 s of its level's first episode")
        return self.env.reset(**kwargs)


def marking_jerk(env, budget, seed):
    """JERK, which first notes the Ray node its level plays on (the first time only) beside the run folder."""
    level = env.unwrapped.state_name
    if "MARKS" in os.environ:
        marks = pathlib.Path(os.environ["MARKS"])
        import ray
        node = ray.get_runtime_context().get_node_id()
        mark = marks / f"{level}.node"
        if not mark.exists():  # written whole, then renamed: the test's driver reads it as it polls
            (marks / f"{level}.tmp").write_text(json.dumps({"level": "Dasher-Genesis/" + level, "node": node}))
            os.replace(marks / f"{level}.tmp", mark)
        if node == (marks / "doomed").read_text():
            env = HeldAfterItsFirstEpisode(env)
    jerk(env, budget, seed)
'''


def test_a_level_whose_node_is_lost_plays_again_on_the_node_left(tmp_path) -> None:
    agents = tmp_path / "marking.py"
    agents.write_text(MARKING_JERK)
    # The level on the removed node is held there after its first episode (under 100 steps on both levels), so
    # a small budget still loses the node mid-level: the retry then plays the whole level again.
    args = ["--benchmark", "dasher", "--levels", "Zone2.Act2,Zone3.Act2", "--timesteps", "200", "--seed", "3",
            "--agent", f"{agents}:marking_jerk"]
    env = {**os.environ, "MARKS": str(tmp_path)}
    script = tmp_path / "lose_a_node.py"
    script.write_text(LOSE_A_NODE)
    # The local run plays while the child starts its cluster (which mostly waits).
    with subprocess.Popen([sys.executable, str(script), str(tmp_path / "ray"), *args], env=env, text=True,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL) as child:
        try:
            assert main(["evaluate", *args, "--workers", "1", "--no-progress", "--out", str(tmp_path / "local")]) == 0
            stdout, stderr = child.communicate(timeout=480)
        finally:
            child.kill()
    assert child.returncode == 0, stdout + stderr
    assert "removed the node of Dasher-Genesis/" in stdout
    assert "was lost" in stdout and "starts again from its beginning" in stdout
    local, ray = ((tmp_path / name / "summary.json").read_bytes() for name in ("local", "ray"))
    assert local == ray

    def episodes(run: str) -> list[tuple]:
        lines = (tmp_path / run / "episodes.jsonl").read_text().splitlines()
        return sorted((e["level"], e["episode"], e["steps"], e["reward"]) for e in map(json.loads, lines))

    assert episodes("ray") == episodes("local")
