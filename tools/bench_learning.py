#!/usr/bin/env python3
"""PPO's training speed on retrokit's vector env against stable-retro's envs, the scores table, the learning check.

Every part prints the machine's load (``/proc/loadavg``) and core count with its figures: the rates follow the
load, the ratios from the same run carry over better.

1. Speed (same machine, same run, interleaved rounds): timesteps per second of Stable-Baselines3's PPO (an agent
   config's hyper-parameters, ``--config``, the horizon cut so a measure holds four updates; the Nature CNN on
   gray 84x84 frames stacked 4; the dasher benchmark's seven actions) trained on Dasher-Genesis with the
   benchmark's rules (frame skip 4, sticky 0.25):

   - ``retrokit``: ``make_vec(...).to_sb3()``, the native vector env with native preprocessing, under
     retrokit's learner view (:mod:`retrokit.learning.sb3task`);
   - ``stable-retro``: stable-retro's env on the integration folder the system tests write for Dasher
     (tests/stable_retro_game.py), the paper's sticky frame skip in Python (tools/bench_env.py), Gymnasium's
     gray, resize and frame-stack wrappers and a discretizer, one per process of SB3's ``SubprocVecEnv``.

   Beside each rate, the env's share of a training step's time: the seconds PPO spent in the envs' steps and
   resets over the seconds of the whole update cycle (``learn``: acting, stepping and the gradient updates).
   The ratio retrokit/stable-retro is the median of the rounds' ratios.

2. Scores (``--scores``): PPO, Joint PPO (``retrokit train`` on the training levels, then ``evaluate --init``),
   Rainbow, for each ``--agent-configs`` (``paper,quick``), and JERK and random, on the dasher benchmark's test
   levels at ``--budget`` timesteps a level: each run's score and final score per level and overall. Run
   folders go to ``--out``; a run whose folder holds a complete ``summary.json`` is read, not run again.

3. Ray (``--ray``): ``retrokit train`` of PPO (``--config``) on the dasher benchmark's training levels, on the
   local backend (SB3 over the native vector env) and on ``--backend ray`` (RLlib's env runners on a local Ray,
   one a level), for ``--ray-updates`` updates each, in this process: the steady timesteps/s of each (from the
   second update on), their ratio, the Ray run's seconds split into its env runners' sampling and its
   learner's updates, and from those what the paper's joint training (188 envs) costs on N machines.

4. The learning check (``--learning``): ``retrokit evaluate --benchmark dasher --agent ppo --agent-config quick
   --levels Zone1.Act2 --timesteps 120000`` and the same with ``--agent random``; PPO's last 20% of episodes must
   score at least 1.5 times random's mean. ``--learning-runs PPO_DIR RANDOM_DIR`` reads two such folders instead.

Usage: python tools/bench_learning.py [--envs 4] [--timesteps 2048] [--rounds 3] [--config quick]
       [--no-speed] [--scores [--budget 10000] [--train-timesteps 30000] [--out DIR]]
       [--ray [--ray-updates 4]] [--learning | --learning-runs P R]
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import gymnasium
import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "tests"))  # the integration writer the system tests use
sys.path.insert(0, str(REPO / "tools"))  # bench_env's sticky frame skip, the paper's

GAME = "Dasher-Genesis"
LEARNING_ARGS = ["--benchmark", "dasher", "--levels", "Zone1.Act2", "--timesteps", "120000", "--workers", "1",
                 "--no-progress"]
LAST_SHARE, FACTOR = 0.2, 1.5


def load() -> str:
    """The machine's load averages and cores, printed with every figure (it is shared)."""
    one, five, fifteen = open("/proc/loadavg").read().split()[:3]  # noqa: SIM115 - a one-line read
    return f"load {one} {five} {fifteen} (1/5/15 min) on {os.cpu_count()} cores, {time.strftime('%Y-%m-%d %H:%M')}"


def dasher():
    """The dasher benchmark and its learning task (the seven actions, the x its reward follows)."""
    from retrokit.benchmark.definition import load_benchmark
    from retrokit.learning.task import learning_task

    benchmark = load_benchmark("dasher")
    return benchmark, learning_task(benchmark)


def stable_retro_env(root: str, name: str, state: str, actions, rules: dict):
    """stable-retro's Dasher as the paper's code made its envs: sticky frame skip in Python, Gymnasium's wrappers.

    Runs in a ``SubprocVecEnv`` child: it registers the integration folder there (a forkserver child does not
    inherit the parent's custom paths).
    """
    import stable_retro
    from bench_env import StickyFrameSkip
    from gymnasium.wrappers import FrameStackObservation, GrayscaleObservation, ResizeObservation, TimeLimit

    class Sticky(gymnasium.Wrapper):
        def __init__(self, env):
            super().__init__(env)
            self.skip = StickyFrameSkip(env, rules["frameskip"], rules["sticky_prob"])

        def reset(self, **kwargs):
            return self.skip.reset(**kwargs)

        def step(self, action):
            return self.skip.step(action)

    class Discrete(gymnasium.ActionWrapper):
        def __init__(self, env):
            super().__init__(env)
            buttons = env.unwrapped.buttons
            self.arrays = [np.array([b in combo for b in buttons], dtype=np.int8) for combo in actions]
            self.action_space = gymnasium.spaces.Discrete(len(actions))

        def action(self, action):
            return self.arrays[int(action)]

    stable_retro.data.Integrations.add_custom_path(root)
    env = stable_retro.make(name, state=state, render_mode=None, use_restricted_actions=stable_retro.Actions.ALL,
                            inttype=stable_retro.data.Integrations.CUSTOM_ONLY)
    env = TimeLimit(Discrete(Sticky(env)), rules["max_episode_steps"])
    return FrameStackObservation(ResizeObservation(GrayscaleObservation(env, keep_dim=False), (84, 84)), 4)


class Timed:
    """Wraps an SB3 VecEnv; adds up the seconds its steps and resets take."""

    @staticmethod
    def wrap(venv):
        from stable_baselines3.common.vec_env import VecEnvWrapper

        class TimedVecEnv(VecEnvWrapper):
            seconds = 0.0

            def reset(self):
                start = time.perf_counter()
                try:
                    return self.venv.reset()
                finally:
                    self.seconds += time.perf_counter() - start

            def step_async(self, actions):
                start = time.perf_counter()
                self.venv.step_async(actions)
                self.seconds += time.perf_counter() - start

            def step_wait(self):
                start = time.perf_counter()
                try:
                    return self.venv.step_wait()
                finally:
                    self.seconds += time.perf_counter() - start

        return TimedVecEnv(venv)


def make_retrokit(envs: int, state: str, reward_scale: float):
    import retrokit
    from retrokit.learning.sb3task import TaskVecEnv

    benchmark, task = dasher()
    rules = {k: v for k, v in benchmark.env_options().items() if k != "scenario_every_frame"}
    native = retrokit.make_vec(GAME, envs, state, grayscale=True, resize=(84, 84), frame_stack=4,
                               channels_first=True, **rules).to_sb3()
    return TaskVecEnv(native, task, reward_scale)


def make_stable_retro(envs: int, root: Path):
    from stable_baselines3.common.vec_env import SubprocVecEnv, VecTransposeImage
    from stable_retro_game import write_integration

    from retrokit.data.games import find_game

    benchmark, task = dasher()
    integration = write_integration(find_game(GAME), root)
    factory = functools.partial(stable_retro_env, str(root), integration.name, integration.state, task.actions,
                                dict(benchmark.env))
    # Gymnasium's FrameStack puts the frames first: (4, 84, 84), what SB3's CNN takes.
    venv = SubprocVecEnv([factory] * envs, start_method="forkserver")
    return (venv if venv.observation_space.shape[0] == 4 else VecTransposeImage(venv)), integration.state


def rate(venv, timesteps: int, config: dict) -> tuple[float, float]:
    """PPO's timesteps/s on ``venv`` over ``timesteps`` after one warm-up update, and the env's share of the time."""
    from retrokit.learning import ppo

    config = dict(config)
    config["horizon"] = max(32, timesteps // venv.num_envs // 4)  # four updates a measure
    config["minibatch"] = min(config["minibatch"], config["horizon"] * venv.num_envs)
    timed = Timed.wrap(venv)
    model = ppo.build(timed, config)
    model.learn(config["horizon"] * venv.num_envs)  # warm-up: caches, the first update's allocations
    timed.seconds = 0.0
    start = time.perf_counter()
    model.learn(timesteps, reset_num_timesteps=False)
    seconds = time.perf_counter() - start
    return timesteps / seconds, timed.seconds / seconds


def speed(envs: int, timesteps: int, rounds: int, config_name: str) -> None:
    from retrokit.learning.config import load_config

    config = load_config("ppo", config_name).values
    print(f"speed: PPO ({config_name} config, {envs} envs, {timesteps} timesteps a measure) on {GAME}; {load()}")
    root = Path(tempfile.mkdtemp(prefix="bench-learning-"))
    theirs, state = make_stable_retro(envs, root)
    ours = make_retrokit(envs, state, config["reward_scale"])
    rates: dict[str, list[tuple[float, float]]] = {"retrokit": [], "stable-retro": []}
    try:
        for turn in range(rounds):  # interleaved, and each round's first side alternates, so drifts in load even out
            sides = [("retrokit", ours), ("stable-retro", theirs)]
            for name, venv in sides if turn % 2 == 0 else sides[::-1]:
                rates[name].append(rate(venv, timesteps, config))
    finally:
        ours.close()
        theirs.close()
    for name, values in rates.items():
        print(f"{name:>13}: {statistics.median(v[0] for v in values):7.1f} timesteps/s of PPO, "
              f"env {statistics.median(v[1] for v in values):.0%} of the update cycle (rounds: "
              + ", ".join(f"{v[0]:.1f}" for v in values) + ")")
    ratios = [a[0] / b[0] for a, b in zip(rates["retrokit"], rates["stable-retro"])]
    print(f"retrokit/stable-retro: {statistics.median(ratios):.2f}x (the rounds' ratios: "
          + ", ".join(f"{r:.2f}" for r in ratios) + f"); {load()}")
    paper_cost(statistics.median(v[0] for v in rates["retrokit"]), f"retrokit's, {config_name} config, {envs} envs")


def paper_cost(timesteps_per_second: float, measured: str) -> None:
    """What the paper's settings mean at the learning check's budget and at its own (1M timesteps a level).

    Its test runs play one env a level (``--config paper --envs 1`` measures that rate).
    """
    from retrokit.learning.config import load_config

    horizon = load_config("ppo", "paper").values["horizon"]  # one env a test level, as the paper's test runs
    for budget in (120_000, 1_000_000):
        print(f"paper config at {budget:,} timesteps a level: {budget // horizon} updates of {horizon} timesteps; "
              f"at {timesteps_per_second:.1f} timesteps/s ({measured}), {budget / timesteps_per_second / 3600:.1f} h a level")


def train_rate(backend: str, config_name: str, updates: int, folder: Path) -> tuple[float, dict[str, float], int]:
    """``retrokit train`` of PPO on the dasher training levels for ``updates`` updates: the steady timesteps/s
    (from the end of the first update to the last) and, on Ray, the seconds of sampling and of learning after
    the first update, and the timesteps after it."""
    from ray.rllib.algorithms.ppo import ppo as rllib_ppo_algorithm
    from ray.rllib.core.learner.learner_group import LearnerGroup

    from retrokit.cli import main
    from retrokit.learning.config import load_config
    from retrokit.learning.trainrun import TrainRun

    config = load_config("ppo", config_name).values
    per_update = config["horizon"] * config["train_envs_per_level"] * len(dasher()[0].train)
    marks: list[tuple[float, int]] = []
    spent = {"sampling": 0.0, "learning": 0.0}

    def timed(kind: str, call):
        def wrapper(*args, **kwargs):
            start = time.perf_counter()
            try:
                return call(*args, **kwargs)
            finally:
                if marks:  # after the first update
                    spent[kind] += time.perf_counter() - start
        return wrapper

    updated = TrainRun.updated
    patches = [(TrainRun, "updated", lambda run, steps: marks.append((time.perf_counter(), steps)) or updated(run, steps)),
               (rllib_ppo_algorithm, "synchronous_parallel_sample",
                timed("sampling", rllib_ppo_algorithm.synchronous_parallel_sample)),
               (LearnerGroup, "update", timed("learning", LearnerGroup.update))]
    saved = [(owner, name, getattr(owner, name)) for owner, name, _ in patches]
    for owner, name, value in patches:
        setattr(owner, name, value)
    try:
        code = main(["train", "--benchmark", "dasher", "--agent", "ppo", "--agent-config", config_name,
                     "--timesteps", str(per_update * updates), "--checkpoint-every", "1e9", "--no-progress",
                     "--backend", backend, "--out", str(folder / backend)])
    finally:
        for owner, name, value in saved:
            setattr(owner, name, value)
    assert code == 0 and len(marks) >= 2, f"train --backend {backend} failed ({code})"
    (t0, s0), (t1, s1) = marks[0], marks[-1]
    return (s1 - s0) / (t1 - t0), spent, s1 - s0


def ray_speed(config_name: str, updates: int) -> None:
    """Part 3: the local and Ray backends' training rates, their ratio, and the paper's joint training's cost."""
    folder = Path(tempfile.mkdtemp(prefix="bench-learning-ray-"))
    print(f"ray: PPO ({config_name} config) trained on dasher's 3 training levels, {updates} updates; {load()}")
    local, _, _ = train_rate("local", config_name, updates, folder)
    ray_rate, spent, steps = train_rate("ray", config_name, updates, folder)
    print(f"local (SB3, native vector env): {local:.1f} timesteps/s; ray (RLlib, 3 env runners): {ray_rate:.1f} "
          f"timesteps/s; ray/local {ray_rate / local:.2f}x; {load()}")
    sampling, learning = steps / spent["sampling"], steps / spent["learning"]
    print(f"ray's update cycle: sampling {spent['sampling']:.1f} s ({sampling:.1f} timesteps/s), learning "
          f"{spent['learning']:.1f} s ({learning:.1f} timesteps/s of the learner)")
    cores = os.cpu_count() or 1
    per_core = sampling / min(3, cores)  # the 3 runners shared this machine's cores with the learner
    for machines in (1, 10, 47, 94):
        rate = 1 / (1 / (per_core * cores * machines) + 1 / learning)
        print(f"{machines:>3} machines of {cores} cores: {rate:,.0f} timesteps/s; 100M timesteps in "
              f"{1e8 / rate / 3600:,.1f} h, 400M in {4e8 / rate / 3600:,.1f} h (the learner: {learning:.0f}/s)")


def command(*args: str) -> list[str]:
    return [sys.executable, "-m", "retrokit", *args]


def finished(folder: Path) -> dict | None:
    """A run folder's ``summary.json`` if the run there is complete."""
    try:
        summary = json.loads((folder / "summary.json").read_text())
    except (OSError, ValueError):
        return None
    return summary if isinstance(summary, dict) and summary.get("complete") else None


def run(folder: Path, args: list[str]) -> float:
    """Run a retrokit command that writes ``folder`` unless a finished run is there; the seconds it took."""
    if finished(folder) is not None or (folder / "policy.json").exists():
        return 0.0
    start = time.perf_counter()
    subprocess.run(command(*args, "--out", str(folder), "--no-progress"), check=True)
    return time.perf_counter() - start


def scores(out: Path, budget: int, train_timesteps: int, configs: list[str], levels: str, workers: int) -> None:
    print(f"scores: dasher's {levels} levels, {budget:,} timesteps a level, Joint PPO trained "
          f"{train_timesteps:,} timesteps on the training levels; {load()}")
    evaluate = ["evaluate", "--benchmark", "dasher", "--levels", levels, "--timesteps", str(budget),
                "--workers", str(workers)]
    rows: list[tuple[str, Path, float]] = []
    from retrokit.learning.config import load_config

    benchmark, _ = dasher()
    for config in configs:
        values = load_config("ppo", config).values
        update = values["horizon"] * values["train_envs_per_level"] * len(benchmark.train)
        if update > train_timesteps:  # retrokit train trains whole updates
            print(f"  note: Joint PPO ({config}) trains whole updates of {update:,} timesteps, "
                  f"not {train_timesteps:,}")
        joint = out / f"train-ppo-{config}"
        seconds = run(joint, ["train", "--benchmark", "dasher", "--agent", "ppo", "--agent-config", config,
                              "--timesteps", str(train_timesteps)])
        print(f"  trained Joint PPO ({config}) in {seconds:.0f} s")
        for label, agent, extra in (("PPO", "ppo", []), ("Joint PPO", "ppo", ["--init", str(joint)]),
                                    ("Rainbow", "rainbow", [])):
            folder = out / f"{label.lower().replace(' ', '-')}-{config}"
            rows.append((f"{label} ({config})", folder,
                         run(folder, [*evaluate, "--agent", agent, "--agent-config", config, *extra])))
    for agent in ("jerk", "random"):
        rows.append((agent if agent == "random" else "JERK", out / agent,
                     run(out / agent, [*evaluate, "--agent", agent])))
    summaries = [(label, finished(folder), seconds) for label, folder, seconds in rows]
    names = list(next(s for _, s, _ in summaries if s)["levels"])
    print("| agent | " + " | ".join(f"{name.split('/')[-1]} score / final" for name in names)
          + " | mean score / final | run s |")
    print("|---|" + "---:|" * (len(names) + 2))
    for label, summary, seconds in summaries:
        cells = [f"{summary['levels'][n]['mean_score']:.0f} / {summary['levels'][n]['final_score']:.0f}"
                 for n in names]
        print(f"| {label} | " + " | ".join(cells)
              + f" | {summary['aggregate']:.0f} / {summary['final_aggregate']:.0f} | {seconds:.0f} |")
    print(f"run folders: {out}; {load()}")


def episodes(folder: Path) -> list[float]:
    return [json.loads(line)["reward"] for line in (folder / "episodes.jsonl").read_text().splitlines() if line]


def learning(ppo_dir: Path, random_dir: Path) -> bool:
    ours, theirs = episodes(ppo_dir), episodes(random_dir)
    last = ours[-max(1, round(len(ours) * LAST_SHARE)):]
    mean_last, mean_random = statistics.fmean(last), statistics.fmean(theirs)
    passed = mean_last >= FACTOR * mean_random
    print(f"PPO (quick): {len(ours)} episodes, mean {statistics.fmean(ours):.1f}, last {LAST_SHARE:.0%} "
          f"({len(last)} episodes) {mean_last:.1f}; random: {len(theirs)} episodes, mean {mean_random:.1f}; "
          f"ratio {mean_last / mean_random:.2f} (needs {FACTOR}): {'passed' if passed else 'FAILED'}")
    return passed


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--envs", type=int, default=4, help="envs of each kind")
    parser.add_argument("--timesteps", type=int, default=2048, help="timesteps of each measure")
    parser.add_argument("--rounds", type=int, default=3, help="rounds of measures")
    parser.add_argument("--config", default="quick", help="the PPO config whose settings the speed part trains with")
    parser.add_argument("--no-speed", action="store_true", help="skip the speed part")
    parser.add_argument("--scores", action="store_true", help="run the scores table (under an hour on 2 cores)")
    parser.add_argument("--budget", type=int, default=10_000, help="scores: timesteps a level (the benchmark's)")
    parser.add_argument("--train-timesteps", type=int, default=30_000, help="scores: Joint PPO's training")
    parser.add_argument("--agent-configs", default="paper,quick", help="scores: the learning agents' configs")
    parser.add_argument("--levels", default="test", help="scores: the levels (test, or LEVEL,...)")
    parser.add_argument("--workers", type=int, default=2, help="scores: evaluate's workers")
    parser.add_argument("--out", type=Path, default=None, help="scores: the run folders (kept; finished runs reused)")
    parser.add_argument("--ray", action="store_true", help="train on the local and the Ray backends (needs RLlib)")
    parser.add_argument("--ray-updates", type=int, default=4, help="ray: the updates of each run")
    parser.add_argument("--learning", action="store_true", help="run the learning check (about 10^5 timesteps)")
    parser.add_argument("--learning-runs", nargs=2, type=Path, metavar=("PPO_DIR", "RANDOM_DIR"),
                        help="read the learning check from these run folders")
    args = parser.parse_args()
    if not args.no_speed:
        speed(args.envs, args.timesteps, args.rounds, args.config)
    if args.ray:
        ray_speed(args.config, args.ray_updates)
    if args.scores:
        out = args.out or Path(tempfile.mkdtemp(prefix="bench-learning-scores-"))
        scores(out, args.budget, args.train_timesteps, args.agent_configs.split(","), args.levels, args.workers)
    if args.learning_runs:
        return 0 if learning(*args.learning_runs) else 1
    if args.learning:
        folder = Path(tempfile.mkdtemp(prefix="bench-learning-"))
        for agent, extra in (("ppo", ["--agent-config", "quick"]), ("random", [])):
            subprocess.run(command("evaluate", "--agent", agent, *extra, *LEARNING_ARGS, "--out", str(folder / agent)),
                           check=True)
        print(load())
        return 0 if learning(folder / "ppo", folder / "random") else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
