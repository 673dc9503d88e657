#!/usr/bin/env python3
"""Vector env throughput: retrokit against stable-retro-turbo, and under a busy CPU.

Env steps per second on Airstriker, frame skip 4, sticky 0.25, no-op actions,
median of ``--rounds`` rounds; each config of each round runs in a fresh
process (so no config inherits another's caches, threads or heap), and the
rounds interleave the configs so that a drift of the machine's speed hits
them all alike.

Configs: 1, 2 and 4 envs, with RGB observations and with gray 84x84 stack 4
ones (made natively: ``make_vec``'s ``grayscale``/``resize``/``frame_stack``), plus 1 env and the 2-env
vector with a third process burning one core (``while True: pass``, as a
learner would).

stable-retro-turbo's ``RetroVecEnv`` runs the same configs side by side when
``--turbo-python`` names an interpreter that imports it (install it in a
venv of its own: it is a fork of stable-retro, which retrokit's venv holds
for its cores), and the ratios retrokit/turbo are printed beside the
targets: >= 2 at 2 and 4 envs, RGB and gray; under load, the 2-env vector
>= 1.2x the 1-env rate.

``--load`` measures only the two configs under load (and the unloaded 2-env
RGB one, to see that a change for the load does not cost the quiet case), so
an A/B of a runner change takes a couple of minutes, not ten.

Usage: python tools/bench_vector.py [--rounds 3] [--seconds 3] [--turbo-python PATH] [--check] [--load]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

GAME = "Airstriker-Genesis"
FRAMESKIP, STICKY = 4, 0.25
#: (envs, observation, loaded): every config measured, in this order.
CONFIGS = [(n, obs, False) for obs in ("rgb", "gray") for n in (1, 2, 4)] + [(1, "rgb", True), (2, "rgb", True)]
RATIO_TARGET = 2.0  # retrokit/turbo at 2 and 4 envs (issue 30)
LOAD_TARGET = 1.2  # 2-env vector / 1 env, both under load


def label(config: tuple[int, str, bool]) -> str:
    n, obs, loaded = config
    shape = "RGB" if obs == "rgb" else "gray 84x84 stack 4"
    return f"{n} env{'s' if n > 1 else ''}, {shape}{', 1 core busy' if loaded else ''}"


# --- the measuring child ------------------------------------------------------------------------


def retrokit_vec(n: int, obs: str):
    """retrokit's vector env of ``n`` envs, gray 84x84 stack 4 made natively inside the step."""
    import retrokit

    options = {"frameskip": FRAMESKIP, "sticky_prob": STICKY}
    if obs == "gray":
        options.update(grayscale=True, resize=(84, 84), frame_stack=4)
    return retrokit.make_vec(GAME, n, **options)


def turbo_vec(n: int, obs: str, rom: str):
    """stable-retro-turbo's vector env, on the ROM retrokit plays (turbo's wheel ships no Airstriker ROM)."""
    import stable_retro

    gray = {"obs_grayscale": True, "obs_resize": (84, 84), "obs_resize_algorithm": "area", "frame_stack": 4}
    vec = stable_retro.RetroVecEnv(
        f"{GAME}-v0", num_envs=n, num_threads=min(n, len(os.sched_getaffinity(0))), render_mode="rgb_array",
        rom_path=rom,
        frame_skip=FRAMESKIP, sticky_action_prob=STICKY, **(gray if obs == "gray" else {}),
    )
    return vec


def game_rom() -> str:
    """The path of the ROM retrokit's env plays."""
    from retrokit.data.games import find_game

    return str(find_game(GAME).rom_path())


def measure(kind: str, n: int, obs: str, seconds: float, rom: str) -> dict:
    """Env steps/s of one vector env stepping no-op actions for about ``seconds``."""
    import numpy as np

    vec = retrokit_vec(n, obs) if kind == "retrokit" else turbo_vec(n, obs, rom)
    space = vec.single_action_space
    actions = np.zeros((n,) + space.shape, dtype=space.dtype)
    vec.reset(seed=0)
    for _ in range(30):  # warm the caches and the threads
        vec.step(actions)
    steps, start = 0, time.perf_counter()
    while (elapsed := time.perf_counter() - start) < seconds:
        for _ in range(10):
            vec.step(actions)
        steps += 10
    vec.close()
    return {"rate": steps * n / elapsed}


# --- the parent ---------------------------------------------------------------------------------


def run_config(python: str, kind: str, config: tuple[int, str, bool], seconds: float, rom: str) -> dict | None:
    """Measure one config in a fresh process, beside a core burner if the config says; None if it failed."""
    n, obs, loaded = config
    burner = subprocess.Popen([sys.executable, "-c", "while True: pass"]) if loaded else None
    try:
        proc = subprocess.run(
            [python, os.path.abspath(__file__), "--child", kind, str(n), obs, "--seconds", str(seconds), "--rom", rom],
            capture_output=True, text=True, timeout=120 + 10 * seconds, check=False,
        )
    except subprocess.TimeoutExpired:
        print(f"  {kind} {label(config)}: timed out", file=sys.stderr)
        return None
    finally:
        if burner is not None:
            burner.kill()
            burner.wait()
    if proc.returncode != 0:
        print(f"  {kind} {label(config)} failed: {proc.stderr.strip().splitlines()[-1:]}", file=sys.stderr)
        return None
    return json.loads(proc.stdout.strip().splitlines()[-1])


def turbo_importable(python: str | None) -> bool:
    if python is None:
        return False
    probe = subprocess.run([python, "-c", "import stable_retro; stable_retro.RetroVecEnv"], capture_output=True, check=False)
    return probe.returncode == 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="rounds (the median is reported)")
    parser.add_argument("--seconds", type=float, default=3.0, help="measured seconds per config per round")
    parser.add_argument("--turbo-python", help="an interpreter that imports stable-retro-turbo's stable_retro")
    parser.add_argument("--check", action="store_true", help="exit 1 if a target is missed")
    parser.add_argument(
        "--load", action="store_true", help="only the configs under load, and 2 envs RGB unloaded beside them"
    )
    parser.add_argument("--child", nargs=3, metavar=("KIND", "N", "OBS"), help=argparse.SUPPRESS)
    parser.add_argument("--rom", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        kind, n, obs = args.child
        print(json.dumps(measure(kind, int(n), obs, args.seconds, args.rom)))
        return 0
    rom = game_rom()

    kinds = {"retrokit": sys.executable}
    if turbo_importable(args.turbo_python):
        kinds["turbo"] = args.turbo_python
    else:
        print("stable-retro-turbo: not measured (pass --turbo-python, an interpreter that imports it)")
    print(f"{len(os.sched_getaffinity(0))} CPUs, load average {os.getloadavg()[0]:.1f} at the start")
    configs = [c for c in CONFIGS if c[2] or c == (2, "rgb", False)] if args.load else CONFIGS
    rates: dict[tuple[str, tuple], list[float | None]] = {}
    for round_ in range(args.rounds):
        for config in configs:
            for kind, python in kinds.items():
                got = run_config(python, kind, config, args.seconds, rom)
                # One entry per round, None where the run failed, so rounds stay aligned for load_ratios.
                rates.setdefault((kind, config), []).append(None if got is None else got["rate"])
        print(f"round {round_ + 1}/{args.rounds} done, load average {os.getloadavg()[0]:.1f}", flush=True)

    def median(kind: str, config: tuple) -> float | None:
        values = [v for v in rates.get((kind, config), []) if v is not None]
        return statistics.median(values) if values else None

    missed = []
    print(f"\nenv steps/s, median of {args.rounds}:")
    print(f"{'config':<40} {'retrokit':>9} {'turbo':>9} {'ratio':>7}  target")
    for config in configs:
        ours, theirs = median("retrokit", config), median("turbo", config)
        ratio = ours / theirs if ours and theirs else None
        target = RATIO_TARGET if config[0] >= 2 and not config[2] else None
        mark = "" if ratio is None or target is None else ("ok" if ratio >= target else "MISSED")
        if mark == "MISSED":
            missed.append(label(config))
        print(
            f"{label(config):<40} {fmt(ours):>9} {fmt(theirs):>9} {fmt(ratio, 2):>7}  "
            f"{f'>= {target} {mark}' if target else ''}"
        )
    print("\nunder load (one core kept busy), 2-env vector / 1 env, the median of each round's ratio:")
    for kind in kinds:
        ratios = load_ratios(rates.get((kind, (1, "rgb", True)), []), rates.get((kind, (2, "rgb", True)), []))
        ratio = statistics.median(ratios) if ratios else None
        mark = "" if kind != "retrokit" or ratio is None else ("ok" if ratio >= LOAD_TARGET else "MISSED")
        if mark == "MISSED":
            missed.append("2-env vector under load")
        rounds = ", ".join(f"{r:.2f}" for r in ratios)
        print(f"  {kind:<9} {fmt(ratio, 2):>6}  {f'>= {LOAD_TARGET} {mark}' if kind == 'retrokit' else '':<12} rounds: {rounds}")
    return 1 if args.check and missed else 0


def load_ratios(one: list[float | None], two: list[float | None]) -> list[float]:
    """Each round's 2-env rate over its 1-env rate, both under load, for the rounds where both ran.

    The two configs of a round run back to back, so a drift of the machine's
    speed (a shared host's neighbours come and go) hits both alike, which a
    ratio of medians taken over the whole run does not promise.
    """
    return [b / a for a, b in zip(one, two) if a and b]


def fmt(value: float | None, digits: int = 0) -> str:
    return "-" if value is None else f"{value:.{digits}f}"


if __name__ == "__main__":
    sys.exit(main())
