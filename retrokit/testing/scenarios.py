"""Checking a game's scenarios: they compile, their tables cover the states, and they run.

For each scenario file:

- **compiles**: it loads and type-checks against the game's fields;
- **table coverage**: every table lookup whose keys are fields or numbers,
  such as ``level_end[zone, act]``, has an entry (or a default) for the keys
  each state starts with;
- **smoke run** (with the ROM), on every state: a fixed seed and scripted
  random inputs for :data:`SMOKE_FRAMES` frames (every :data:`HOLD_STEPS` steps,
  one combination of each group of the scenario's ``actions``, or of the
  system's default groups, which hold no console switch); rewards must be finite, done
  must not hold at the first step, and no run-time error (a division by zero,
  a missing table entry) may happen;
- **deterministic**: a second identical run gives the same rewards, dones and RAM.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from retrokit.data.games import Game
from retrokit.errors import RetrokitError, ScenarioRuntimeError
from retrokit.testing.report import FAIL, PASS, SKIP, GameReport

__all__ = ["SMOKE_FRAMES", "SMOKE_SEED", "SmokeRun", "check_scenarios", "lookups", "smoke_run"]

SMOKE_FRAMES = 600  # frames of scripted random play per state and scenario
SMOKE_FRAMESKIP = 4
SMOKE_SEED = 0
HOLD_STEPS = 6  # a random action is held this many steps, so the game sees deliberate inputs


@dataclass
class SmokeRun:
    """What one smoke run did.

    Attributes:
        rewards: Every player's reward at each step.
        dones: Done at each step.
        ram: The system RAM at the end.
        error: The error that stopped the run, or ``""``.
        error_step: The step the error happened at (0: at reset).
    """

    rewards: list[tuple[float, ...]] = field(default_factory=list)
    dones: list[bool] = field(default_factory=list)
    ram: bytes = b""
    error: str = ""
    error_step: int = -1


def check_scenarios(
    game: Game, report: GameReport, starts: Mapping[str, Mapping[str, int]], *, rom: bool, frames: int = SMOKE_FRAMES,
    progress: Callable[[str], None] | None = None,
) -> None:
    """Check every scenario of the game; add the results to ``report``.

    Args:
        game: The game.
        report: Where results go.
        starts: Each usable state's field values at its start (from loading or parsing it).
        rom: Whether the ROM is available (smoke runs need it).
        frames: Frames per smoke run.
        progress: Told which scenario and state each smoke run is on.
    """
    from retrokit.dsl.scenario import load_scenario

    if not game.scenarios:
        report.add("scenarios", SKIP, "the game has no scenario files")
        return
    if not rom:
        report.add("smoke run", SKIP, "no ROM: scenarios were compiled and their tables checked, not run "
                   "(import the ROM to run them: retrokit import /path/to/roms)")
    for name, path in game.scenarios.items():
        try:
            load_scenario(path, list(game.fields), game_dir=path.parent)
        except RetrokitError as exc:
            report.add("scenario compiles", FAIL, str(exc), scenario=name)
            continue
        report.add("scenario compiles", PASS, f"{path.name} compiles against {len(game.fields)} fields", scenario=name)
        _check_tables(report, name, path, starts)
        if rom:
            for state in starts:
                if progress is not None:
                    progress(f"{name} on {state}")
                _check_runs(game, report, name, path, state, frames)


# --- Tables ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LookupSite:
    """A table lookup in a scenario: the table, its key expressions (as field names or numbers), where it is."""

    table: str
    keys: tuple[str | int | float | None, ...]  # None: a key computed by an expression
    where: str


def lookups(path: Path) -> tuple[dict[str, Any], list[LookupSite]]:
    """Return a YAML scenario's tables and every lookup in its expressions (nothing for Gym Retro JSON)."""
    from retrokit.dsl.document import load_document
    from retrokit.dsl.nodes import Lookup, Name, Number, walk
    from retrokit.dsl.parser import parse

    if path.suffix.lower() not in (".yaml", ".yml"):
        return {}, []
    spec = load_document(path)
    snippets = [*spec.defines.values(), *spec.rewards, *([spec.done] if spec.done is not None else [])]
    sites = []
    for snippet in snippets:
        for node in walk(parse(snippet)):
            if isinstance(node, Lookup):
                keys = tuple(
                    k.id if isinstance(k, Name) else k.value if isinstance(k, Number) else None for k in node.keys
                )
                sites.append(LookupSite(node.table, keys, snippet.where(node.start)))
    return spec.tables, sites


def _check_tables(report: GameReport, scenario: str, path: Path, starts: Mapping[str, Mapping[str, int]]) -> None:
    tables, sites = lookups(path)
    if not sites:
        return
    if not starts:
        report.add("table coverage", SKIP, "no state's start values are known", scenario=scenario)
        return
    for site in sites:
        table = tables[site.table]
        if None in site.keys:
            report.add("table coverage", SKIP, f"{site.table} at {site.where}: a key is computed, not a field",
                       scenario=scenario)
            continue
        names = table.by or tuple(str(k) for k in site.keys)
        missing = []
        for state, values in starts.items():
            if any(isinstance(k, str) and k not in values for k in site.keys):
                continue  # a definition or counter, not a field: known only when running
            key = tuple(values[k] if isinstance(k, str) else k for k in site.keys)
            if key not in table.entries and table.default is None:
                missing.append(state)
                shown = ", ".join(f"{n}={v}" for n, v in zip(names, key))
                report.add("table coverage", FAIL,
                           f"expected table {site.table!r} to have an entry for {shown}, where this state starts "
                           f"(looked up at {site.where}); found none. Add one at {table.origin.where()} "
                           "or give the table a default.", state=state, scenario=scenario)
        if not missing:
            report.add("table coverage", PASS,
                       f"{site.table}[{', '.join(map(str, site.keys))}] has an entry for all {len(starts)} states",
                       scenario=scenario)


# --- Smoke runs --------------------------------------------------------------------------------------


def smoke_run(game: Game, state: str, scenario: Path, *, frames: int = SMOKE_FRAMES, seed: int = SMOKE_SEED) -> SmokeRun:
    """Play ``frames`` frames of scripted random inputs from a state under a scenario; return what happened.

    The run stops at done, and at the first error (recorded, not raised).
    """
    from retrokit.envs.env import make  # the env layer's make, not the root package's: testing sits below it

    run = SmokeRun()
    env = None
    step = 0
    try:
        # The scenario's action groups, or the system's: what an agent plays with, never a console switch
        # (a 2600's SELECT ends the game) unless the scenario lists one.
        env = make(game, state, str(scenario), obs_type="ram", frameskip=SMOKE_FRAMESKIP,
                   sticky_prob=0.25, players=game.players, action_type="multi_discrete")
        env.action_space.seed(seed)
        obs, _ = env.reset(seed=seed)
        action = env.action_space.sample()
        for step in range(1, frames // SMOKE_FRAMESKIP + 1):
            if step % HOLD_STEPS == 0:
                action = env.action_space.sample()
            obs, reward, terminated, _, info = env.step(action)
            run.rewards.append(tuple(info["rewards"]) if "rewards" in info else (reward,))
            run.dones.append(bool(terminated))
            if terminated:
                break
        run.ram = bytes(np.asarray(obs))
    except ScenarioRuntimeError as exc:
        run.error, run.error_step = str(exc), step
    except RetrokitError as exc:
        run.error, run.error_step = f"{type(exc).__name__}: {exc}", step
    finally:
        if env is not None:
            env.close()
    return run


def _check_runs(game: Game, report: GameReport, scenario: str, path: Path, state: str, frames: int) -> None:
    first = smoke_run(game, state, path, frames=frames)
    if first.error:
        when = "at reset" if first.error_step == 0 else f"at step {first.error_step}"
        report.add("smoke run", FAIL, f"a run-time error {when}: {first.error}", state=state, scenario=scenario)
        return
    bad = _first_non_finite(first.rewards)
    if bad is not None:
        report.add("smoke run", FAIL, f"expected finite rewards; found {first.rewards[bad]} at step {bad + 1}. "
                   "Guard the expression that makes it.", state=state, scenario=scenario)
        return
    if first.dones[:1] == [True]:
        report.add("smoke run", FAIL, "expected the episode to go on after its first step; done was already true. "
                   "Check the done condition against this state's start values.", state=state, scenario=scenario)
        return
    total = [sum(r[i] for r in first.rewards) for i in range(len(first.rewards[0]))] if first.rewards else [0.0]
    ended = f"done at step {len(first.dones)}" if first.dones and first.dones[-1] else f"{len(first.dones)} steps"
    report.add("smoke run", PASS, f"{ended}, total reward {', '.join(f'{t:g}' for t in total)}",
               state=state, scenario=scenario)
    second = smoke_run(game, state, path, frames=frames)
    differs = _difference(first, second)
    if differs:
        report.add("deterministic", FAIL, f"expected two runs with the same seed and inputs to agree; {differs}. "
                   "Something depends on more than the state and the inputs.", state=state, scenario=scenario)
    else:
        report.add("deterministic", PASS, "two runs gave the same rewards, dones and RAM", state=state,
                   scenario=scenario)


def _first_non_finite(rewards: Sequence[tuple[float, ...]]) -> int | None:
    for i, values in enumerate(rewards):
        if not all(math.isfinite(v) for v in values):
            return i
    return None


def _difference(a: SmokeRun, b: SmokeRun) -> str:
    if a.error != b.error:
        return f"the second run ended with {b.error or 'no error'!r}"
    for i, (x, y) in enumerate(zip(a.rewards, b.rewards)):
        if x != y:
            return f"the rewards differ at step {i + 1}: {x} and {y}"
    if a.dones != b.dones:
        return f"done came at step {len(a.dones)} in one run and {len(b.dones)} in the other"
    if a.ram != b.ram:
        at = next(i for i, (x, y) in enumerate(zip(a.ram, b.ram)) if x != y) if len(a.ram) == len(b.ram) else 0
        return f"the RAM differs at the end (first at offset {at:#x})"
    return ""
