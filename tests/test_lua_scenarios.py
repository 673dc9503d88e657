"""The Lua-scripted scenarios of the stable-retro wheel, against their rewrites in ``games/``.

Each wheel scenario file that names Lua functions (``"script": "lua:f"``) has a
retrokit scenario of the same name in ``games/<Game>/``. Here the original
``script.lua`` runs in LuaJIT (through lupa), driven as Gym Retro's C++ drives
it (``src/data.cpp``, ``src/script-lua.cpp``, the ``GameData`` glue of
``src/retro-c.cpp``):

- an env reset restarts the scenario and reloads its scripts: a fresh Lua
  state whose globals are what the file sets; ``update_ram`` then runs
  ``Scenario::update`` once, its results dropped;
- each env step (one frame) runs ``Scenario::update``: ``done`` first, then
  the reward, each from its script function if it has one, else from the
  scenario.json variables by Gym Retro's rules (transcribed below);
- ``data.<name>`` (the ``__index`` of the ``data`` table) reads a field's
  value; ``scenario.frame`` counts the updates since the restart, 0 at reset.

The retrokit scenario is found through its game, as ``retrokit.make`` finds
it, so the ``games/`` file must shadow the wheel's. It gets the same field
values through ``Run.reset`` and ``Run.step(values, frame=i, step=i)``.
Random trajectories mix holding still, small and large steps, the numbers
written in the Lua and JSON (and their neighbours), and values anywhere in the
field's type. Rewards and dones must be equal at every step; a Lua error or
NaN must be a ``ScenarioRuntimeError`` at the same step.
"""

from __future__ import annotations

import json
import math
import random
import re
from pathlib import Path

import pytest

from retrokit import paths
from retrokit.data.games import find_game
from retrokit.dsl.scenario import load_scenario
from retrokit.errors import ScenarioRuntimeError

lupa = pytest.importorskip("lupa")
try:
    from lupa import luajit21 as lua_module  # Gym Retro embeds Lua 5.1; LuaJIT speaks it
except ImportError:  # pragma: no cover - lupa wheels bundle LuaJIT
    lua_module = lupa

REPO = Path(__file__).resolve().parents[1]
#: Covered by tests/test_sonic_scenarios.py (their scripts write to ``data``, which this harness refuses).
HAND_CHECKED = ("SonicTheHedgehog-Genesis", "SonicTheHedgehog2-Genesis", "SonicAndKnuckles3-Genesis")
SEEDS = 12
STEPS = 150


def lua_scenario_files() -> list[tuple[str, Path]]:
    """Every wheel scenario file using Lua, as (game name, file)."""
    found = []
    for kind in paths.wheel_data_dirs():
        for path in sorted(kind.glob("*/*.json")):
            if path.name in ("data.json", "metadata.json"):
                continue
            data = json.loads(path.read_text())
            if "scripts" in data and re.sub(r"-v\d+$", "", path.parent.name) not in HAND_CHECKED:
                found.append((re.sub(r"-v\d+$", "", path.parent.name), path))
    return found


CASES = lua_scenario_files()
CUSTOM_SONIC = [(g, p) for g, p in CASES if g.startswith("Sonic")]


# --- Gym Retro's rules for what a script does not compute (data.cpp, utils.cpp) ----------------------

OPS = {
    "": lambda v, r: v,
    "equal": lambda v, r: int(v == r),
    "negative-equal": lambda v, r: int(v == -r),
    "not-equal": lambda v, r: int(v != r),
    "less-than": lambda v, r: int(v < r),
    "greater-than": lambda v, r: int(v > r),
    "less-or-equal": lambda v, r: int(v <= r),
    "greater-or-equal": lambda v, r: int(v >= r),
    "nonzero": lambda v, r: int(v != 0),
    "zero": lambda v, r: int(v == 0),
    "positive": lambda v, r: int(v > 0),
    "negative": lambda v, r: int(v < 0),
    "sign": lambda v, r: (v > 0) - (v < 0),
}


def measured(spec: dict, value: int, delta: int, default: str) -> int:
    """Scenario::calculate: the value or the change, through the op."""
    use = delta if spec.get("measurement", default) == "delta" else value
    return OPS[spec.get("op", "")](use, spec.get("reference", 0))


def rule_done(node: dict, values: dict, deltas: dict) -> bool:
    """Scenario::calculateDone and isDone: variables, then nodes, by any or all."""
    tests = [measured(s, values[n], deltas[n], "absolute") > 0 for n, s in node.get("variables", {}).items()]
    tests += [rule_done(sub, values, deltas) for sub in node.get("nodes", {}).values()]
    return all(tests) if node.get("condition") == "all" else any(tests)


def rule_reward(spec: dict, values: dict, deltas: dict) -> float:
    """Scenario::calculateReward without a script: each variable's change times reward or penalty."""
    total = 0.0
    for name, var in spec.get("variables", {}).items():
        m = float(measured(var, values[name], deltas[name], "delta"))
        total += m * (var.get("reward", 0) if m > 0 else var.get("penalty", 0) if m < 0 else 0)
    if "time" in spec:
        m = float(measured(spec["time"], 1, 1, "delta"))
        total += m * (spec["time"].get("reward", 0) if m > 0 else spec["time"].get("penalty", 0) if m < 0 else 0)
    return total


# --- The original, in Lua ----------------------------------------------------------------------------

HOST = """
local fields, frame = {}, 0
function retrokit_set_step(values, f) fields, frame = values, f end
data = setmetatable({}, {
  __index = function(_, name)
    local value = fields[name]
    if value == nil then error("no variable " .. tostring(name)) end
    return value
  end,
  __newindex = function(_, name) error("this test does not model writes to data." .. tostring(name)) end,
})
scenario = setmetatable({}, {
  __index = function(_, name)
    if name == "frame" then return frame end
    if name == "timestep" then return math.floor(frame / 4) end
    error("Unknown scenario property")
  end,
  __newindex = function() end,
})
"""


def script_function(spec: dict) -> str | None:
    script = spec.get("script")
    return None if script is None else script.split(":", 1)[-1]


def run_gym_retro(path: Path, reset: dict, steps: list[dict]) -> list:
    """Per step ``(reward, done)`` as Gym Retro computes them, ending in "error" at a Lua error or NaN.

    An error in the update at reset makes the list ``["error"]``.
    """
    data = json.loads(path.read_text())
    runtime = lua_module.LuaRuntime()
    runtime.execute(HOST)
    for script in data["scripts"]:
        runtime.execute((path.parent / script).read_text())
    lua = runtime.globals()
    reward_spec, done_spec = data.get("reward", {}), data.get("done", {})
    reward_fn, done_fn = script_function(reward_spec), script_function(done_spec)
    out: list = []
    last = reset
    for frame, values in enumerate([reset, *steps]):
        deltas = {name: values[name] - last[name] for name in values}
        lua.retrokit_set_step(runtime.table_from(values), frame)
        try:
            done = lua[done_fn]() if done_fn else rule_done(done_spec, values, deltas)
            reward = lua[reward_fn]() if reward_fn else rule_reward(reward_spec, values, deltas)
        except lua_module.LuaError:
            return [*out, "error"]
        if math.isnan(reward):
            return [*out, "error"]
        assert isinstance(done, bool) and isinstance(reward, (int, float)), (done, reward)
        if frame:  # the update at reset is dropped
            out.append((float(reward), done))
        last = values
    return out


def run_retrokit(game: str, scenario: str, reset: dict, steps: list[dict]) -> list:
    """Per step ``(reward, done)`` of the game's scenario of that name, ending in "error" at a runtime error."""
    found = find_game(game)
    run = load_scenario(found.scenario_path(scenario), list(found.fields)).start()
    out: list = []
    try:
        run.reset(reset)
        for i, values in enumerate(steps, 1):
            (reward,), done = run.step(values, i, i)
            out.append((reward, done))
    except ScenarioRuntimeError:
        out.append("error")
    return out


# --- Trajectories ------------------------------------------------------------------------------------


def type_range(code: str) -> tuple[int, int]:
    """The values a field of this type code can hold: ``|u1``, ``>i2``, ``<d3`` (BCD), ``>n5``."""
    kind, size = code[1], int(code[2:])
    if kind == "i":
        return -(1 << (8 * size - 1)), (1 << (8 * size - 1)) - 1
    if kind in "dn":
        return 0, 10 ** (2 * size if kind == "d" else size) - 1
    return 0, (1 << (8 * size)) - 1


def constants(path: Path) -> list[int]:
    """The numbers written in a scenario and its scripts, with their neighbours, and 0, 1, -1."""
    data = json.loads(path.read_text())
    text = path.read_text() + "".join((path.parent / s).read_text() for s in data["scripts"])
    numbers = {int(n, 0) for n in re.findall(r"(?<![\w.])(0x[0-9A-Fa-f]+|\d+)(?![\w.])", text)}
    return sorted({n + d for n in numbers | {0} for d in (-1, 0, 1)})


def level_ends(path: Path) -> dict[tuple[int, int], int]:
    """A Sonic script's level_max_x by (zone, act), entries commented out skipped."""
    text = (path.parent / "script.lua").read_text()
    found = re.findall(r'^\s*\["zone=(\d+),act=(\d+)"\]\s*=\s*([^,]+),', text, re.MULTILINE)
    return {(int(z), int(a)): sum(int(part, 0) for part in end.split("+")) for z, a, end in found}


#: Sonic's stage fields and their value in a normal level (special and bonus stages end contest episodes).
SONIC_STAGE_FLAGS = {"special_stage": 0, "game_mode": 12}


def trajectory(path: Path, fields: dict, seed: int) -> tuple[dict, list[dict]]:
    """Field values at reset and at each of STEPS steps."""
    rng = random.Random(seed)
    special = constants(path)
    ranges = {name: type_range(spec.type) for name, spec in fields.items()}

    def move(name: str, value: int) -> int:
        r = rng.random()
        if r < 0.5:
            return value
        if r < 0.7:
            return value + rng.randint(-2, 5)
        if r < 0.8:
            return value + rng.randint(-50, 500)
        if r < 0.95:
            return rng.choice(special)
        return rng.randint(*ranges[name])

    reset = {name: rng.choice(special) if rng.random() < 0.5 else rng.randint(0, 20) for name in fields}
    levels = level_ends(path) if "level_max_x" in (path.parent / "script.lua").read_text() else {}
    if levels:
        sonic_reset(rng, reset, levels)
    steps = []
    for _ in range(STEPS):
        previous = steps[-1] if steps else reset
        values = {name: move(name, v) for name, v in previous.items()}
        if rng.random() < 0.05:  # several fields at one number at once, as at a game over (for "all" dones)
            shared = rng.choice(special)
            values.update((name, shared) for name in values if rng.random() < 0.7)
        if levels:
            sonic_step(rng, previous, values, special)
        steps.append(values)
    return reset, steps


def sonic_reset(rng: random.Random, values: dict, levels: dict[tuple[int, int], int]) -> None:
    """Sonic at reset: in a level the table knows, mostly before its end, in no special stage."""
    zone, act = rng.choice(sorted(levels))
    end = levels[zone, act]
    x = rng.randrange(0, end - 0x80) if rng.random() < 0.8 else end + rng.randrange(-0x400, 0x40)
    values.update(zone=zone, act=act, lives=rng.choice([2, 3, 3, 3, 4]), x=x, screen_x=max(0, x - 0xA0))
    values.update((flag, calm) for flag, calm in SONIC_STAGE_FLAGS.items() if flag in values)


def sonic_step(rng: random.Random, previous: dict, values: dict, special: list[int]) -> None:
    """Sonic runs back and forth in his level; now and then a life, a stage, or an act change."""
    dx = rng.randrange(-60, 100)
    values.update(zone=previous["zone"], act=previous["act"], lives=previous["lives"])
    values.update(x=max(0, previous["x"] + dx), screen_x=max(0, previous["screen_x"] + dx))
    if rng.random() < 0.01:
        values["lives"] += rng.choice([-1, 1])
    for flag, calm in SONIC_STAGE_FLAGS.items():
        if flag in values:
            toggled = rng.choice(special) if previous[flag] == calm else calm
            values[flag] = toggled if rng.random() < 0.03 else previous[flag]
    if rng.random() < 0.02:  # Sonic 3 & Knuckles changes act midway: x jumps back with the camera
        jump = rng.randrange(0, 0x1000)
        values.update(act=1 - values["act"] if values["act"] < 2 else values["act"])
        values.update(x=max(0, values["x"] - jump), screen_x=max(0, values["screen_x"] - jump))


# --- Tests -------------------------------------------------------------------------------------------


def test_every_lua_scenario_has_a_rewrite() -> None:
    """49 files at stable-retro 1.0: every one is found, and its game resolves it to games/."""
    assert len(CASES) >= 49
    for game, path in CASES:
        resolved = find_game(game).scenario_path(path.stem)
        assert resolved.is_relative_to(REPO / "games" / game), (game, resolved)


@pytest.mark.parametrize("game,path", CASES, ids=[f"{g}-{p.stem}" for g, p in CASES])
def test_rewrite_matches_the_lua(game: str, path: Path) -> None:
    fields = dict(find_game(game).fields)
    seen_rewards, seen_dones = set(), set()
    for seed in range(SEEDS):
        reset, steps = trajectory(path, fields, seed)
        expected, got = run_gym_retro(path, reset, steps), run_retrokit(game, path.stem, reset, steps)
        assert got == expected, f"seed {seed}: first difference at step {_first_difference(expected, got) + 1}"
        seen_rewards |= {(r > 0) - (r < 0) for r, _ in (s for s in expected if s != "error")}
        seen_dones |= {d for _, d in (s for s in expected if s != "error")}
    # The trajectories exercise the scenario: rewards earned and not, episodes ending and not.
    assert {0, 1} <= seen_rewards and seen_dones == {False, True}, (seen_rewards, seen_dones)


def _first_difference(a: list, b: list) -> int:
    return next((i for i, (x, y) in enumerate(zip(a, b)) if x != y), min(len(a), len(b)))


@pytest.mark.parametrize("game,path", CUSTOM_SONIC, ids=[g for g, _ in CUSTOM_SONIC])
@pytest.mark.parametrize("where", ["unknown_level", "at_the_end"])
def test_custom_sonic_fails_where_the_lua_fails(game: str, path: Path, where: str) -> None:
    """A level missing from the table (nil in Lua), or a start at its end (0/0 is NaN): both refuse at reset."""
    fields = find_game(game).fields
    zone, act = (30, 2) if where == "unknown_level" else min(level_ends(path))
    x = 0x100 if where == "unknown_level" else level_ends(path)[zone, act]
    reset = {**dict.fromkeys(fields, 0), "zone": zone, "act": act, "x": x, "lives": 3, "game_mode": 12}
    reset = {name: reset[name] for name in fields}
    steps = [{**reset, "x": reset["x"] + 8 * i} for i in range(1, 4)]
    assert run_gym_retro(path, reset, steps) == ["error"]
    assert run_retrokit(game, path.stem, reset, steps) == ["error"]
