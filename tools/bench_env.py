#!/usr/bin/env python3
"""Env speed, as four ratios measured in one run on Airstriker.

It first says which Genesis core the env runs: the one ``retrokit build-core
genesis_plus_gx`` makes (it skips drawing the 3 frames of a step nobody
sees) or the stable-retro wheel's (it draws all 4).

1. retrokit's env (RGB observation, frame skip 4, sticky 0.25, reward, done
   and info) against the raw native rate of 4-frame runs of the same core,
   told the same frames are seen (target >= 0.95).
2. The env's step time against 4 raw rendered frames of the wheel's core
   (target <= 0.5 with the patched core, which skips the sound nobody hears
   too; with the wheel's it is about 1).
   Beside it, this machine's floor for it: the patched core's raw 4-frame
   runs drawing only the last frame, against the wheel's.
3. The same env against stable-retro's env in a Python sticky frame-skip
   wrapper like the paper's (target >= 2.8 with the patched core, 1.3 with
   the wheel's, which both run). The env can beat stable-retro by no more
   than its core's raw native rate does; that ceiling (raw/stable-retro,
   same bursts) is printed beside it. It depends on the CPU: the core's share
   of a frame against Python's.
4. A 2-env threaded vector against 1 env, in env steps/s (target >= 1.85).

Beside them, with no target: an 8-env vector against the 2-env one (the
machine has two CPUs, so 8 envs share 2 threads; the figure shows that more
envs than CPUs keep the throughput: it was 0.4 when each env had a thread),
and the 2-env vector against 1 env when the scenario runs every frame, as
the Sonic preset's does (the vector then runs one frame per native call);
and the observation agents train on, gray 84x84 stacked 4, made natively
(``gray84x84x4``; ``-max`` with the max of a step's last two frames, so a
second frame drawn), against the RGB env, and against the same made by
Gymnasium's wrappers around it.

These machines are noisy and their speed drifts from one second to the
next, so each ratio alternates its own kinds in short bursts (short enough
that both see the same machine, long enough that each runs with its own data
in the caches, as in real use, and with no third kind's data in the way). A
round measures every ratio; the median over rounds is reported. Every kind
plays the same frames: the bare emulators restart from the start state as
often as the envs' no-op episodes end.

Beside the third figure it prints the machine's own ceiling for it too, from the
same rounds: two bare emulators run at once by the native runner against one.
On a virtual machine whose second vCPU is often busy elsewhere, that ceiling
swings between about 1.2 and 2 from one second to the next, and no vector env
can beat it; so the vector figure is also given over the rounds in which the
machine gave two full cores (a ceiling of 1.9 or more), if there were any.
The same two emulators run without waiting for each other after every step
(one runner call per burst) show what the lockstep itself costs there: when
either vCPU is held up, a vector env's other thread waits for it.

Usage: python tools/bench_env.py [--ticks 4] [--burst 25] [--rounds 25] [--many 8] [--check]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable

import gymnasium
import numpy as np

import retrokit
from retrokit.data.games import find_game
from retrokit.data.statecheck import load_state
from retrokit.host.cores import locate_core, wheel_core
from retrokit.host.emulator import Emulator
from retrokit.native import _host
from retrokit.paths import wheel_dir

GAME = "Airstriker-Genesis"
OPTIONS = {"frameskip": 4, "sticky_prob": 0.25, "obs_type": "rgb"}
RATIOS = {  # name: (faster kind, baseline kind, target); a "time" ratio is the baseline's rate over the faster's
    "env/raw": ("env", "raw", 0.95),
    "env time/wheel raw time": ("env", "raw-wheel", 0.5),
    "env/stable-retro": ("env", "stable-retro", 2.8),
    "vector2/env": ("vector2", "env", 1.85),
}
TIME_RATIOS = {"env time/wheel raw time"}  # lower is better
WHEEL_TARGETS = {"env time/wheel raw time": None, "env/stable-retro": 1.3}  # with the wheel's core: nothing to skip
CEILINGS = {  # name: (kinds of the machine's own ceiling for it, measured in the same bursts)
    "env time/wheel raw time": ("raw", "raw-wheel"),
    "env/stable-retro": ("raw", "stable-retro"),
    "vector2/env": ("raw2", "raw"),
}
FULL_CORES = 1.9  # a ceiling this high means the machine gave both threads a core
GRAY84X84X4 = {"grayscale": True, "resize": (84, 84), "frame_stack": 4}


class StickyFrameSkip:
    """The paper's sticky frame-skip wrapper, in Python, around stable-retro's env."""

    def __init__(self, env, n: int = 4, stickprob: float = 0.25) -> None:
        self.env, self.n, self.stickprob = env, n, stickprob
        self.rng = np.random.default_rng(0)
        self.curac = None
        self.action_space = env.action_space

    def reset(self, **kwargs):
        self.curac = None
        return self.env.reset(**kwargs)

    def step(self, ac):
        total, terminated, truncated, info = 0.0, False, False, {}
        for i in range(self.n):
            if self.curac is None or (i == 0 and self.rng.random() > self.stickprob) or i == 1:
                self.curac = ac
            obs, rew, terminated, truncated, info = self.env.step(self.curac)
            total += rew
            if terminated or truncated:
                break
        return obs, total, terminated, truncated, info


Stepper = Callable[[int], int]  # runs n env steps of its kind; returns how many env steps that made


def gym_gray84x84x4(env):
    """Gray 84x84 stacked 4 the way a user without native preprocessing makes it: Gymnasium's wrappers."""
    from gymnasium.wrappers import FrameStackObservation, GrayscaleObservation, ResizeObservation

    return FrameStackObservation(ResizeObservation(GrayscaleObservation(env), (84, 84)), 4)


def env_stepper(env) -> Stepper:
    """Steps of a single env (reset when an episode ends)."""
    action = env.action_space.sample() * 0
    env.reset(seed=0)

    def steps(n: int) -> int:
        for _ in range(n):
            _, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                env.reset()
        return n

    return steps


def vector_stepper(vec) -> Stepper:
    actions = np.zeros((vec.num_envs,) + vec.single_action_space.shape, dtype=vec.single_action_space.dtype)
    vec.reset(seed=0)

    def steps(n: int) -> int:
        for _ in range(n):
            vec.step(actions)
        return n * vec.num_envs

    return steps


def episode_length(env) -> int:
    """Steps of one no-op episode of the env (the game is deterministic from its state)."""
    action = env.action_space.sample() * 0
    env.reset(seed=0)
    steps, done = 0, False
    while not done:
        _, _, terminated, truncated, _ = env.step(action)
        steps, done = steps + 1, terminated or truncated
    return steps


class Bare:
    """Bare emulators run by the native runner, restarting from the state every ``episode`` steps.

    They restart as the envs do when their episode ends, so that all kinds
    emulate the same frames: the frames after Airstriker's game over cost a
    few percent less than its play.
    """

    def __init__(self, state: bytes, rom, count: int, episode: int, core=None, video: str = "last") -> None:
        self.state, self.episode, self.done = state, episode, 0
        self.emus = [Emulator("Genesis", rom, core_path=core) for _ in range(count)]
        for emu in self.emus:
            emu.set_state(state)
            emu.set_video_frames(video)  # as the env tells its core: only a step's last frame is seen
        self.natives = [emu.handle for emu in self.emus]
        self.actions = np.zeros((count, 2), dtype=np.uint16)
        self.runner = _host.Runner(count - 1)

    def run(self, steps: int) -> None:
        """Run ``steps`` 4-frame steps in one runner call, split where an episode ends."""
        while steps:
            now = min(steps, self.episode - self.done % self.episode)
            if len(self.natives) == 1:
                self.natives[0].run(self.actions[0], 4 * now)
            else:
                self.runner.run(self.natives, self.actions, 4 * now)
            self.done += now
            steps -= now
            if self.done % self.episode == 0:
                for emu in self.emus:
                    emu.set_state(self.state)

    def lockstep(self, n: int) -> int:
        """n steps, one call each: every emulator waits for the others after each step, as a vector env's do."""
        for _ in range(n):
            self.run(1)
        return n * len(self.emus)

    def free(self, n: int) -> int:
        """n steps in as few calls as the episodes allow: the emulators wait for each other only at the end."""
        self.run(n)
        return n * len(self.emus)

    def close(self) -> None:
        for emu in self.emus:
            emu.close()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ticks", type=int, default=4, help="ticks per round")
    parser.add_argument("--burst", type=int, default=25, help="steps of each kind per tick")
    parser.add_argument("--rounds", type=int, default=25, help="rounds")
    parser.add_argument("--many", type=int, default=8, help="envs of the many-env vector (0: skip it)")
    parser.add_argument("--check", action="store_true", help="exit 1 if a ratio misses its target")
    args = parser.parse_args()

    folder = wheel_dir() / "data" / "stable" / "Airstriker-Genesis-v0"
    state = load_state(find_game(GAME), folder / "Level1.state")  # the wheel's: no probe
    env = retrokit.make(GAME, **OPTIONS)
    vec = retrokit.make_vec(GAME, 2, **OPTIONS)
    episode = episode_length(env)
    found = locate_core("genesis_plus_gx")
    patched = env.emulator.av_asked > 0  # a core that never asks GET_AUDIO_VIDEO_ENABLE draws every frame
    print(f"core: {found.path} ({found.origin}{', ' + found.note if found.note else ''}); "
          + ("it skips drawing the frames nobody sees" if patched else
             "it draws every frame (build the patched one: retrokit build-core genesis_plus_gx)"))
    if not patched:
        RATIOS.update({name: (*RATIOS[name][:2], target) for name, target in WHEEL_TARGETS.items()})
    bares = [Bare(state, folder / "rom.md", n, episode) for n in (1, 2, 2)]
    bares.append(Bare(state, folder / "rom.md", 1, episode, core=wheel_core("genesis_plus_gx"), video="all"))
    kinds: dict[str, Stepper] = {
        "raw": bares[0].lockstep, "raw2": bares[1].lockstep, "raw2-free": bares[2].free,
        "raw-wheel": bares[3].lockstep, "env": env_stepper(env), "vector2": vector_stepper(vec),
    }
    many = retrokit.make_vec(GAME, args.many, **OPTIONS) if args.many else None
    if many is not None:
        kinds[f"vector{args.many}"] = vector_stepper(many)
    per_frame = {**OPTIONS, "scenario_every_frame": True}
    extras = [retrokit.make(GAME, **per_frame), retrokit.make_vec(GAME, 2, **per_frame)]
    kinds["env-pf"], kinds["vector2-pf"] = env_stepper(extras[0]), vector_stepper(extras[1])
    extras.append(retrokit.make(GAME, **OPTIONS, **GRAY84X84X4))
    kinds["gray84x84x4"] = env_stepper(extras[-1])
    extras.append(retrokit.make(GAME, **OPTIONS, **GRAY84X84X4, max_pool=True))
    kinds["gray84x84x4-max"] = env_stepper(extras[-1])
    try:
        extras.append(gym_gray84x84x4(retrokit.make(GAME, **OPTIONS)))
        kinds["gym-gray84x84x4"] = env_stepper(extras[-1])
    except gymnasium.error.DependencyNotInstalled:  # ResizeObservation needs opencv (the test extra has it)
        pass
    try:
        import stable_retro

        kinds["stable-retro"] = env_stepper(StickyFrameSkip(stable_retro.make("Airstriker-Genesis-v0", render_mode=None)))
    except ImportError:
        pass

    groups = {"env/raw": ["env", "raw"], "env time/wheel raw time": ["env", "raw-wheel", "raw"],
              "env/stable-retro": ["env", "stable-retro", "raw"],
              "vector2/env": ["vector2", "env", "raw2", "raw", "raw2-free"]}  # the vector's ceilings, same bursts
    notes = {"vector2-pf/env-pf": "the scenario every frame, one frame per native call"}
    groups["vector2-pf/env-pf"] = ["vector2-pf", "env-pf"]
    groups["gray84x84x4/env"] = ["gray84x84x4", "env"]
    notes["gray84x84x4/env"] = "gray 84x84 stack 4, made natively, against RGB"
    groups["gray84x84x4-max/env"] = ["gray84x84x4-max", "env"]
    notes["gray84x84x4-max/env"] = "the same with max_pool (a second frame drawn a step) against RGB"
    groups["gray84x84x4/gym-gray84x84x4"] = ["gray84x84x4", "gym-gray84x84x4"]
    notes["gray84x84x4/gym-gray84x84x4"] = "the same made natively against Gymnasium's wrappers around the RGB env"
    if many is not None:
        groups[f"vector{args.many}/vector2"] = [f"vector{args.many}", "vector2"]
        notes[f"vector{args.many}/vector2"] = f"{args.many} envs sharing this machine's CPUs"
    groups = {name: kinds_ for name, kinds_ in groups.items() if all(k in kinds for k in kinds_)}
    rates: dict[str, dict[str, list[float]]] = {name: {k: [] for k in ks} for name, ks in groups.items()}
    for round_ in range(args.rounds + 1):  # round 0 warms up
        for name, group in groups.items():
            elapsed = dict.fromkeys(group, 0.0)
            steps = dict.fromkeys(group, 0)
            for _ in range(args.ticks):
                for kind in group:
                    stepper = kinds[kind]
                    start = time.perf_counter()
                    steps[kind] += stepper(args.burst)
                    elapsed[kind] += time.perf_counter() - start
            if round_:
                for kind in group:
                    rates[name][kind].append(steps[kind] / elapsed[kind])

    for kind in kinds:
        values = [v for group in rates.values() for v in group.get(kind, [])]
        print(f"{kind:>14}: {statistics.median(values):8.1f} env steps/s (median of its measurements)")
    failed = False
    for name, (top, bottom, target) in RATIOS.items():
        if name not in rates:
            print(f"{name:>24}: skipped (stable-retro is not installed)")
            continue
        group = rates[name]
        timed = name in TIME_RATIOS
        ratio = statistics.median((b / t if timed else t / b) for t, b in zip(group[top], group[bottom]))
        if target is None:
            print(f"{name:>24}: {ratio:6.3f}  (no target: this core has nothing to skip)")
        else:
            ok = ratio <= target if timed else ratio >= target
            failed |= not ok
            print(f"{name:>24}: {ratio:6.3f}  (target {'<=' if timed else '>='} {target}) {'ok' if ok else 'MISSED'}")
        if name in CEILINGS:
            c_top, c_bottom = CEILINGS[name]
            ceilings = [(b / t if timed else t / b) for t, b in zip(group[c_top], group[c_bottom])]
            label = f"{c_top} time/{c_bottom} time" if timed else f"{c_top}/{c_bottom}"
            print(f"{label:>24}: {statistics.median(ceilings):6.3f}  (this machine's {'floor' if timed else 'ceiling'} "
                  "for it, same rounds)")
            if name != "vector2/env":
                continue
            unlocked = statistics.median(f / b for f, b in zip(group["raw2-free"], group[c_bottom]))
            print(f"{'raw2-free/' + c_bottom:>24}: {unlocked:6.3f}  (the same without waiting for each other every step)")
            free = [t / b for t, b, c in zip(group[top], group[bottom], ceilings) if c >= FULL_CORES]
            if free:
                print(f"{name:>24}: {statistics.median(free):6.3f}  in the {len(free)} rounds with two full cores "
                      f"(ceiling >= {FULL_CORES})")
            else:
                print(f"{'':>24}  no round had two full cores (ceiling >= {FULL_CORES})")
    for name in groups:
        if name not in RATIOS:
            group = rates[name]
            top, bottom = groups[name]
            ratio = statistics.median(t / b for t, b in zip(group[top], group[bottom]))
            print(f"{name:>24}: {ratio:6.3f}  (no target: {notes[name]})")
    env.close()
    vec.close()
    if many is not None:
        many.close()
    for extra in extras:
        extra.close()
    for bare in bares:
        bare.close()
    return 1 if args.check and failed else 0


if __name__ == "__main__":
    sys.exit(main())
