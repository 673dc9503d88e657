#!/usr/bin/env python3
"""Benchmark retrokit's Atari 2600 env against ale-py's, the same settings on both sides, ratios from one run.

Both sides play the same ROM file (ale-py's, imported into a temporary data
folder, its bytes checked equal) with RGB observations (210x160x3), frame
skip 4 (4 frames emulated a step, no max-pooling of the last two), sticky
actions 0.25 and ale-py's full action space (its 18 joystick and fire
combinations; retrokit's ``action_type="discrete"`` is the same 18), random
actions, resets when an episode ends:

- ``retrokit``: ``retrokit.make(game, frameskip=4, sticky_prob=0.25, action_type="discrete")``;
- ``ale-py``: ``gymnasium.make("ALE/<Game>-v5", frameskip=4, repeat_action_probability=0.25,
  full_action_space=True)`` (v5 draws sticky actions each frame, Gym Retro's rule on a step's first:
  the emulation is the same work);
- the 2-env vectors: ``retrokit.make_vec(game, 2, ...)`` and ale-py's ``AtariVectorEnv(game, 2,
  ...)`` with 210x160 RGB, stack 1, no max-pooling, no no-op starts, no reward clipping,
  no fire reset, one thread per env.

Before timing, each side's emulated frames per step are counted and must be
4, and its observations must be 210x160x3: the two sides do the same work
(an earlier version of this script compared ale-py without sticky actions, and
with its 6-action set, which is not the same work). Each round times every config
for ``--seconds`` in turn (interleaved, so a drift of the machine hits them
alike); the figures are the medians over rounds of env steps a second (a
vector's step is 2 env steps), and each ratio is the median of the rounds'
ratios. The load average is printed before and after.

Then resets a second from each game's default state (``env.reset()``), as the
descriptor has them (Pong and Breakout reload the game: their paddles), as
they were before (every ROM reloading), and ale-py's.

Usage: PYTHONPATH=. python tools/bench_atari.py [--rounds 5] [--seconds 2] [--resets 100]
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

GAMES = {"Pong": "pong", "Breakout": "breakout"}  # retrokit's name -> ale-py's ROM
RESET_GAMES = {**GAMES, "Freeway": "freeway"}  # Freeway: joysticks, so its resets load no game
FRAMESKIP, STICKY, ACTIONS = 4, 0.25, 18
SHAPE = (210, 160, 3)


def load() -> str:
    """The load averages, as uptime prints them."""
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f}, {five:.2f}, {fifteen:.2f} ({os.cpu_count()} CPUs)"


class Side:
    """One config: an env (or a 2-env vector) stepped with random actions, resetting when an episode ends."""

    def __init__(self, step: Callable[[np.ndarray], None], frames: Callable[[], int], envs: int, close: Callable[[], None]):
        self.step, self.frames, self.envs, self.close = step, frames, envs, close
        self.actions = np.random.default_rng(0).integers(0, ACTIONS, size=(4096, envs))

    def rate(self, seconds: float) -> float:
        """Env steps a second over about ``seconds``."""
        steps, start = 0, time.perf_counter()
        while (elapsed := time.perf_counter() - start) < seconds:
            for i in range(32):
                self.step(self.actions[(steps + i) % len(self.actions)])
            steps += 32
        return steps * self.envs / elapsed


def retrokit_env(game: str) -> Side:
    import retrokit

    env = retrokit.make(f"{game}-Atari2600", frameskip=FRAMESKIP, sticky_prob=STICKY, action_type="discrete")
    assert env.action_space.n == ACTIONS and env.observation_space.shape == SHAPE
    env.reset(seed=0)

    def step(action: np.ndarray) -> None:
        if any(env.step(int(action[0]))[2:4]):
            env.reset()

    return Side(step, lambda: env.unwrapped.emulator.frame, 1, env.close)


def retrokit_vec(game: str) -> Side:
    import retrokit

    vec = retrokit.make_vec(f"{game}-Atari2600", 2, frameskip=FRAMESKIP, sticky_prob=STICKY, action_type="discrete")
    assert vec.single_observation_space.shape == SHAPE
    vec.reset(seed=0)
    return Side(vec.step, lambda: sum(e.unwrapped.emulator.frame for e in vec.envs), 2, vec.close)


def ale_env(rom: str) -> Side:
    import ale_py
    import gymnasium

    gymnasium.register_envs(ale_py)
    name = "".join(part.capitalize() for part in rom.split("_"))
    env = gymnasium.make(f"ALE/{name}-v5", frameskip=FRAMESKIP, repeat_action_probability=STICKY,
                         full_action_space=True, obs_type="rgb")
    assert env.action_space.n == ACTIONS and env.observation_space.shape == SHAPE
    env.reset(seed=0)
    ale = env.unwrapped.ale

    def step(action: np.ndarray) -> None:
        if any(env.step(int(action[0]))[2:4]):
            env.reset()

    return Side(step, ale.getFrameNumber, 1, env.close)


def ale_vec(rom: str) -> Side:
    from ale_py.vector_env import AtariVectorEnv

    vec = AtariVectorEnv(rom, 2, img_height=SHAPE[0], img_width=SHAPE[1], grayscale=False, stack_num=1,
                         frameskip=FRAMESKIP, maxpool=False, noop_max=0, repeat_action_probability=STICKY,
                         full_action_space=True, reward_clipping=False, use_fire_reset=False, episodic_life=False,
                         num_threads=2)
    assert vec.single_action_space.n == ACTIONS and vec.single_observation_space.shape[-3:] == SHAPE
    vec.reset(seed=0)
    frames = [0]

    def step(actions: np.ndarray) -> None:
        info = vec.step(actions)[4]
        frames[0] = int(np.sum(info["frame_number"]))

    return Side(step, lambda: frames[0], 2, vec.close)


def frames_per_step(side: Side, steps: int = 200) -> float:
    """Frames each env emulates a step (it autoresets along the way: a few frames more or less)."""
    side.step(side.actions[0])
    before = side.frames()
    for i in range(steps):
        side.step(side.actions[i % len(side.actions)])
    return (side.frames() - before) / steps / side.envs


def bench_steps(rounds: int, seconds: float) -> None:
    configs = {(game, who, n): make(game if who == "retrokit" else rom)
               for game, rom in GAMES.items()
               for who, n, make in (("retrokit", 1, retrokit_env), ("ale-py", 1, ale_env),
                                    ("retrokit", 2, retrokit_vec), ("ale-py", 2, ale_vec))}
    for key, side in configs.items():
        fps = frames_per_step(side)
        assert abs(fps - FRAMESKIP) < 0.1, f"{key}: {fps:.2f} frames a step, not {FRAMESKIP}"
        print(f"  {key[0]:<9} {key[1]:<9} {key[2]} env{'s' if key[2] > 1 else ' '}: {fps:.2f} frames a step")
    rates: dict[tuple[str, str, int], list[float]] = {key: [] for key in configs}
    for r in range(rounds):
        for key, side in configs.items():
            rates[key].append(side.rate(seconds))
        print(f"  round {r + 1}/{rounds} done; {load()}", flush=True)
    print(f"\nenv steps/s, median of {rounds} rounds; ratio: median of the rounds' retrokit/ale-py, the same kind "
          "of env; targets (issue 43): the env >= 1.0x ale-py's, the 2-env vector >= 2.0x ale-py's env")
    print(f"{'game':<9} {'envs':>4}  {'retrokit':>9}  {'ale-py':>9}  {'ratio':>6}  {'vs ale-py env':>13}  {'target':>6}")
    for game in GAMES:
        single = rates[(game, "ale-py", 1)]
        for n, target in ((1, 1.0), (2, 2.0)):
            ours, theirs = rates[(game, "retrokit", n)], rates[(game, "ale-py", n)]
            ratio = statistics.median(a / b for a, b in zip(ours, theirs, strict=True))
            to_env = statistics.median(a / b for a, b in zip(ours, single, strict=True))
            print(f"{game:<9} {n:>4}  {statistics.median(ours):>9,.0f}  {statistics.median(theirs):>9,.0f}  "
                  f"{ratio:>5.2f}x  {to_env:>12.2f}x  {target:>5.1f}x")
    for side in configs.values():
        side.close()


def reset_rate(reset: Callable[[], object], resets: int) -> float:
    reset()
    start = time.perf_counter()
    for _ in range(resets):
        reset()
    return resets / (time.perf_counter() - start)


def bench_resets(rounds: int, resets: int) -> None:
    import ale_py
    import gymnasium

    import retrokit

    gymnasium.register_envs(ale_py)
    print(f"\nresets/s from the default state (env.reset()), median of {rounds} rounds of {resets}")
    print(f"{'game':<9}  {'retrokit':>9}  {'reloading':>9}  {'ale-py':>8}  {'vs reloading':>12}  {'vs ale-py':>9}")
    for game, rom in RESET_GAMES.items():
        env = retrokit.make(f"{game}-Atari2600", frameskip=FRAMESKIP, action_type="discrete")
        name = "".join(part.capitalize() for part in rom.split("_"))
        ale = gymnasium.make(f"ALE/{name}-v5", frameskip=FRAMESKIP, repeat_action_probability=STICKY,
                             full_action_space=True)
        emulator = env.unwrapped.emulator
        rule = emulator.reloads_states
        ours, before, theirs = [], [], []
        for _ in range(rounds):
            ours.append(reset_rate(env.reset, resets))
            emulator._reload_states = True  # the earlier rule: every ROM's state load reloaded the game
            before.append(reset_rate(env.reset, resets))
            emulator._reload_states = rule
            theirs.append(reset_rate(ale.reset, resets))
        env.close()
        ale.close()
        print(f"{game:<9}  {statistics.median(ours):>9,.0f}  {statistics.median(before):>9,.0f}  "
              f"{statistics.median(theirs):>8,.0f}  "
              f"{statistics.median(a / b for a, b in zip(ours, before, strict=True)):>11.2f}x  "
              f"{statistics.median(a / b for a, b in zip(ours, theirs, strict=True)):>8.2f}x")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--seconds", type=float, default=2.0)
    parser.add_argument("--resets", type=int, default=100)
    args = parser.parse_args()
    os.environ["RETROKIT_DATA"] = tempfile.mkdtemp(prefix="bench-atari-data-")
    import ale_py

    from retrokit.cli import main as cli

    with contextlib.redirect_stdout(io.StringIO()) as said:  # its list of the ROMs it matched no game to
        if cli(["import", "--from", "ale-py"]) != 0:
            print(said.getvalue())
            return 1
    for game, rom in RESET_GAMES.items():
        ours = Path(os.environ["RETROKIT_DATA"]) / "roms" / f"{game}-Atari2600" / "rom.a26"
        assert ours.read_bytes() == (Path(ale_py.__file__).parent / "roms" / f"{rom}.bin").read_bytes(), game
    print(f"\nbefore: {load()}\nframes each env emulates a step (checked {FRAMESKIP} on both sides):")
    bench_steps(args.rounds, args.seconds)
    bench_resets(args.rounds, args.resets)
    print(f"\nafter: {load()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
