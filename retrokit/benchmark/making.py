"""A benchmark file made from a game, and a benchmark file checked: ``retrokit benchmark new`` and ``validate``.

A game's states are its levels. Unless told which to train and test on, the
states are split as the shipped benchmarks split theirs (the paper's
protocol holds levels out for testing): states named alike but for their last
number (``Zone1.Act1``, ``Zone1.Act2``; ``Level2-1``, ``Level2-2``) are one
zone, whose last state is held out for testing and the others trained on; a
game whose states share no such zone trains and tests on all of them. A
variant of a state (``Level1-1.2P`` beside ``Level1-1``: another player
count) is left out. The env rules are the protocol's (the Sonic preset's),
the scenario the game's default one; a scenario that lists ``actions`` gets
``action_type: filtered``, so agents press only those.
"""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from dataclasses import dataclass

from retrokit.benchmark.definition import Benchmark, Level, read_benchmark
from retrokit.data.games import Game
from retrokit.envs.sonic import FRAMESKIP, MAX_EPISODE_STEPS, STICKY_PROB
from retrokit.errors import InvalidArgumentError, RetrokitError, StateNotFoundError, did_you_mean

PROTOCOL_BUDGET = 1_000_000  # the paper's timesteps per level
MAX_BUDGET = 10**12
_LAST_NUMBER = re.compile(r"^(.*?)(\d+)(\D*)$")


@dataclass(frozen=True)
class Made:
    """A benchmark made from a game, and how its levels were chosen (one line, for the user)."""

    benchmark: Benchmark
    split: str


def split_states(states: Sequence[str]) -> tuple[list[str], list[str], str]:
    """The protocol's split of a game's states: train, test, and how it was made (see the module's doc)."""
    names = set(states)
    levels = [s for s in states if "." not in s or s.rpartition(".")[0] not in names]
    zones: dict[tuple[str, str], list[tuple[int, str]]] = {}
    for state in levels:
        match = _LAST_NUMBER.match(state)
        key = (match.group(1), match.group(3)) if match else (state, "")
        zones.setdefault(key, []).append((int(match.group(2)) if match else 0, state))
    if not any(len(zone) > 1 for zone in zones.values()):
        return levels, levels, f"{len(levels)} state(s) sharing no zone: each trained and tested on"
    train, test = [], []
    for zone in zones.values():
        ordered = [state for _, state in sorted(zone)]
        if len(ordered) > 1:
            test.append(ordered[-1])
        train.extend(ordered[:-1] if len(ordered) > 1 else ordered)
    return train, test, f"the last state of each zone held out to test ({len(test)}), the others to train ({len(train)})"


def make_benchmark(
    game: Game,
    train: Sequence[str] | None = None,
    test: Sequence[str] | None = None,
    *,
    budget: int = PROTOCOL_BUDGET,
    max_episode_steps: int = MAX_EPISODE_STEPS,
    scenario: str | None = None,
) -> Made:
    """A benchmark of ``game``: its levels (the protocol's split unless given), rules, scenario and budget.

    Raises:
        StateNotFoundError: A level named is not a state of the game (or the game has none).
        UnknownNameError: The scenario named is not one of the game's.
        InvalidArgumentError: The budget or episode length is out of range, or the game has no scenario.
    """
    from retrokit.dsl.scenario import load_scenario

    for what, number, high in (("--budget", budget, MAX_BUDGET), ("--max-episode-steps", max_episode_steps, 10**9)):
        if not isinstance(number, int) or isinstance(number, bool) or not 1 <= number <= high:
            raise InvalidArgumentError(f"Expected {what} from 1 to {high:,}; got {number!r}.")
    states = game.states
    if not states:
        raise StateNotFoundError(
            f"Expected states of {game.name} to make its levels; found none. Make one first: "
            "retrokit ramsearch savestate NAME --default (or retrokit integrate)."
        )
    for name in [*(train or ()), *(test or ())]:
        if name not in states:
            raise StateNotFoundError(
                f"Expected a state of {game.name} ({', '.join(states)}) as a level; got {name!r}."
                + did_you_mean(name, states)
            )
    auto_train, auto_test, how = split_states(states)
    if train is not None or test is not None:
        how = "as given"
    train_names = list(train) if train is not None else (auto_train if test is None else [s for s in auto_train if s not in test])
    test_names = list(test) if test is not None else auto_test
    if not test_names:
        raise InvalidArgumentError(f"Expected at least one test level; {game.name}'s --train took every state.")
    path = game.scenario_path(scenario)  # the default one unless named: refuses a name the game lacks
    env: dict[str, object] = {
        "frameskip": FRAMESKIP, "sticky_prob": STICKY_PROB, "max_episode_steps": max_episode_steps,
        "scenario_every_frame": True,
    }  # fmt: skip
    if scenario is not None:
        env["scenario"] = scenario
    if load_scenario(path, list(game.fields)).actions:  # a retrokit scenario or a Gym Retro one
        env["action_type"] = "filtered"
    benchmark = Benchmark(
        name=game.name.lower(),
        train=tuple(Level(game.name, s) for s in dict.fromkeys(train_names)),
        test=tuple(Level(game.name, s) for s in dict.fromkeys(test_names)),
        budget=budget,
        env=env,
        description=f"{game.name}: {len(dict.fromkeys(train_names))} level(s) to train, "
        f"{len(dict.fromkeys(test_names))} to test, {budget:,} timesteps per level",
    )
    return Made(benchmark, how)


def benchmark_text(made: Made) -> str:
    """The benchmark file's text, with a comment for each choice made for the user."""
    bench = made.benchmark
    lines = [
        f"# A benchmark of {bench.test[0].game}, written by `retrokit benchmark new`: check it with",
        "# `retrokit validate FILE`, run it with `retrokit evaluate --benchmark FILE` (retrokit docs evaluate).",
        f"# Levels: {made.split}.",
        f"name: {bench.name}",
        f"description: {json.dumps(bench.description)}",
        f"budget: {bench.budget}            # timesteps per level (the paper's protocol: 1000000)",
        "env:",
        "  # The protocol's rules (the Sonic preset's): 4 frames a step, sticky frame skip, bounded episodes.",
    ]
    lines += [f"  {key}: {str(value).lower() if isinstance(value, bool) else value}" for key, value in bench.env.items()]
    lines += ["levels:"]
    for split, levels in (("train", bench.train), ("test", bench.test)):
        lines += [f"  {split}:", *(f"    - {level.name}" for level in levels)]
    return "\n".join(lines) + "\n"


def check_benchmark(path: str) -> list[str]:
    """Check a benchmark file: its shape, its levels' games, states and ROMs, and each level's env starting.

    Returns:
        One line per level that cannot start (empty: every level starts).

    Raises:
        BenchmarkFileError: The file is not a benchmark file.
        RetrokitError: A level's game, state or ROM is missing (named with the fix).
    """
    from retrokit.envs.env import RetroEnv

    bench = read_benchmark(path)
    levels = bench.levels()
    bench.check_levels(levels)
    problems = []
    for level in levels:
        options = bench.env_options()
        try:
            env = RetroEnv(level.game, level.state, options.pop("scenario", None), **options)
            try:
                env.reset(seed=0)
            finally:
                env.close()
        except (RetrokitError, TypeError, ValueError) as exc:  # a bad option's value is the file's fault
            problems.append(f"{level.name}: {exc}")
    return problems


def is_benchmark_file(target: str) -> bool:
    """Whether a ``validate`` target names a benchmark file (a YAML file that is not a game's data file)."""
    from pathlib import Path

    path = Path(target)
    return path.suffix in (".yaml", ".yml") and path.name != "game.yaml" and path.is_file()

