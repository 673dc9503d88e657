"""Gym Retro scenario.json files: every op, on hand-made RAM, against Gym Retro's rules.

The reference below is a plain transcription of Gym Retro's ``src/data.cpp``
(``Scenario::calculateReward``, ``calculateDone``, ``RewardSpec::calculate``,
``DoneSpec::test``) and ``src/utils.cpp`` (``calculate``): it is what the
converter must reproduce, step by step, for JSON loaded directly and for the
YAML the converter writes.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from retrokit.dsl import convert_scenario_json
from retrokit.dsl.scenario import load_scenario

OPS = [None, "equal", "negative-equal", "not-equal", "less-than", "greater-than", "less-or-equal",
       "greater-or-equal", "nonzero", "zero", "positive", "negative", "sign"]

# A field's values: at reset, then at each step. Deltas: 0, 10, -20, 30, 0, -15, -10, 5, 10, 3.
V = [0, 0, 10, -10, 20, 20, 5, -5, 0, 10, 13]
FIELDS = ["v", "w", "lives"]


# --- Gym Retro's rules, transcribed -----------------------------------------------------------------


def calculate(op: str | None, reference: int, value: int) -> int:
    """utils.cpp ``calculate``."""
    return {
        None: value,
        "equal": value == reference,
        "negative-equal": value == -reference,
        "not-equal": value != reference,
        "less-than": value < reference,
        "greater-than": value > reference,
        "less-or-equal": value <= reference,
        "greater-or-equal": value >= reference,
        "nonzero": value != 0,
        "zero": value == 0,
        "positive": value > 0,
        "negative": value < 0,
        "sign": (value > 0) - (value < 0),
    }[op]


def measured(spec: dict, value: int, delta: int, default: str) -> int:
    use_delta = spec.get("measurement", default) == "delta"
    return int(calculate(spec.get("op"), spec.get("reference", 0), delta if use_delta else value))


def reward_of(spec: dict, value: int, delta: int) -> float:
    """RewardSpec::calculate: positive results times reward, negative times penalty."""
    m = float(measured(spec, value, delta, "delta"))
    if m < 0:
        return m * spec.get("penalty", 0)
    if m > 0:
        return m * spec.get("reward", 0)
    return m


def done_of(node: dict, values: dict, deltas: dict) -> bool:
    """Scenario::isDone of a node: variables, then nodes, combined by its condition."""
    every = node.get("condition") == "all"
    results = [measured(s, values[n], deltas[n], "absolute") > 0 for n, s in node.get("variables", {}).items()]
    results += [done_of(sub, values, deltas) for sub in node.get("nodes", {}).values()]
    return all(results) if every else any(results)


def gym_retro(data: dict, reset: dict, steps: list[dict], frames_per_step: int = 1) -> list[tuple[tuple[float, ...], bool]]:
    """Per step: per-player rewards (variables plus time per frame) and done."""
    players = data.get("rewards") or [data.get("reward", {})]
    out, last = [], reset
    for values in steps:
        deltas = {name: values[name] - last[name] for name in values}
        rewards = []
        for reward in players:
            total = sum(reward_of(s, values[n], deltas[n]) for n, s in reward.get("variables", {}).items())
            if "time" in reward:
                total += reward_of(reward["time"], 1, 1) * frames_per_step
            rewards.append(total)
        out.append((tuple(rewards), done_of(data.get("done", {}), values, deltas)))
        last = values
    return out


def ram(vs: list[int], **others: list[int]) -> tuple[dict, list[dict]]:
    rows = [{"v": v, "w": others.get("w", [0] * len(vs))[i], "lives": others.get("lives", [3] * len(vs))[i]} for i, v in enumerate(vs)]
    return rows[0], rows[1:]


def retrokit(source, reset: dict, steps: list[dict], frames_per_step: int = 1) -> list[tuple[tuple[float, ...], bool]]:
    run = load_scenario(source, FIELDS).start()
    run.reset(reset)
    return [run.step(values, frames_per_step * i, i) for i, values in enumerate(steps, 1)]


def both_ways(tmp_path: Path, data: dict, reset: dict, steps: list[dict], frames_per_step: int = 1) -> list:
    """Results of the JSON loaded directly; they must equal those of the converted YAML."""
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(data, indent=2))
    direct = retrokit(path, reset, steps, frames_per_step)
    converted = tmp_path / "scenario.yaml"
    converted.write_text(convert_scenario_json(path))
    assert retrokit(converted, reset, steps, frames_per_step) == direct
    assert retrokit(data, reset, steps, frames_per_step) == direct  # a parsed dict, recognised as Gym Retro's
    return direct


# --- Every op ---------------------------------------------------------------------------------------


def _op_id(op: str | None) -> str:
    return op or "no-op"


@pytest.mark.parametrize("measurement", [None, "absolute", "delta"], ids=lambda m: m or "default")
@pytest.mark.parametrize("op", OPS, ids=_op_id)
@pytest.mark.parametrize("reward,penalty", [(2.5, 0.5), (3.0, 0.0), (0.0, 2.0), (1.5, 1.5)], ids=["both", "reward", "penalty", "equal"])
def test_reward_ops(tmp_path, op, measurement, reward, penalty) -> None:
    spec = {"reward": reward, "penalty": penalty, "reference": 10}
    spec.update({"op": op} if op else {})
    spec.update({"measurement": measurement} if measurement else {})
    data = {"reward": {"variables": {"v": spec}}}
    reset, steps = ram(V)
    assert both_ways(tmp_path, data, reset, steps) == gym_retro(data, reset, steps)


@pytest.mark.parametrize("measurement", [None, "absolute", "delta"], ids=lambda m: m or "default")
@pytest.mark.parametrize("op", OPS, ids=_op_id)
@pytest.mark.parametrize("reference", [10, -10, 0])
def test_done_ops(tmp_path, op, measurement, reference) -> None:
    spec = {"reference": reference}
    spec.update({"op": op} if op else {})
    spec.update({"measurement": measurement} if measurement else {})
    data = {"done": {"variables": {"v": spec}}}
    reset, steps = ram(V)
    assert both_ways(tmp_path, data, reset, steps) == gym_retro(data, reset, steps)


def test_reward_ops_tell_apart_every_step(tmp_path) -> None:
    """The hand-made RAM makes every comparison both true and false somewhere."""
    reset, steps = ram(V)
    for op in OPS[1:-1]:
        for measurement in ("absolute", "delta"):
            data = {"reward": {"variables": {"v": {"op": op, "reference": 10, "reward": 1, "measurement": measurement}}}}
            assert {r for (r,), _ in gym_retro(data, reset, steps)} == {0.0, 1.0}, (op, measurement)


@pytest.mark.parametrize(
    "condition,nodes,expected_kind",
    [
        ("any", {}, "any"),
        ("all", {}, "all"),
        ("any", {"inner": {"condition": "all", "variables": {"w": {"op": "positive"}, "lives": {"op": "less-than", "reference": 3}}}}, "any"),
        ("all", {"a": {"variables": {"w": {"op": "zero"}}}, "b": {"nodes": {"c": {"variables": {"lives": {"op": "zero"}}}}}}, "all"),
    ],
    ids=["any", "all", "any_with_all_node", "all_with_nested_nodes"],
)
def test_done_conditions_and_nodes(tmp_path, condition, nodes, expected_kind) -> None:
    data = {"done": {"condition": condition, "variables": {"v": {"op": "greater-than", "reference": 0}}, "nodes": nodes}}
    reset, steps = ram(V, w=[0, 1, 0, 2, 0, 0, 3, 0, 0, 1, 0], lives=[3, 3, 2, 2, 0, 0, 2, 0, 3, 0, 0])
    results = both_ways(tmp_path, data, reset, steps)
    assert results == gym_retro(data, reset, steps)
    assert {done for _, done in results} == {True, False}


@pytest.mark.parametrize("condition,expected", [("any", False), ("all", True)])
def test_empty_done(tmp_path, condition, expected) -> None:
    """Gym Retro's quirk: with nothing to test, 'all' is always done and 'any' never."""
    data = {"done": {"condition": condition}}
    reset, steps = ram(V)
    assert all(done is expected for _, done in both_ways(tmp_path, data, reset, steps))


@pytest.mark.parametrize(
    "time",
    [{"reward": -0.01}, {"penalty": 1.0}, {"op": "sign", "reward": 0.5}, {"op": "negative-equal", "reference": 1, "reward": 2.0},
     {"op": "greater-than", "reference": 0, "reward": 0.25, "penalty": 9.0}],
    ids=["reward", "penalty_only_has_no_effect", "sign", "never", "greater_than"],
)
@pytest.mark.parametrize("frames_per_step", [1, 4])
def test_time_term_per_frame(tmp_path, time, frames_per_step) -> None:
    data = {"reward": {"variables": {"v": {"reward": 1.0}}, "time": time}}
    reset, steps = ram(V)
    assert both_ways(tmp_path, data, reset, steps, frames_per_step) == gym_retro(data, reset, steps, frames_per_step)


def test_per_player_rewards(tmp_path) -> None:
    data = {
        "rewards": [{"variables": {"v": {"reward": 1.0}}}, {"variables": {"w": {"reward": 2.0, "penalty": 1.0}}}],
        "done": {"variables": {"lives": {"op": "zero"}}},
    }
    reset, steps = ram(V, w=[0, 5, 0, 2, 2, 9, 3, 0, 0, 1, 0])
    results = both_ways(tmp_path, data, reset, steps)
    assert results == gym_retro(data, reset, steps)
    assert load_scenario(data, FIELDS).players == 2


def test_reward_and_rewards_merge_like_gym_retro(tmp_path) -> None:
    """rewards[0] adds to reward: a variable already set keeps reward's spec."""
    data = {"reward": {"variables": {"v": {"reward": 1.0}}}, "rewards": [{"variables": {"v": {"reward": 100.0}, "w": {"reward": 3.0}}}]}
    reset, steps = ram(V, w=[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10])
    merged = {"reward": {"variables": {"v": {"reward": 1.0}, "w": {"reward": 3.0}}}}
    assert both_ways(tmp_path, data, reset, steps) == gym_retro(merged, reset, steps)


def test_actions_and_crop(tmp_path) -> None:
    actions = [[["LEFT"], ["RIGHT"], []], [["A"], []]]
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps({"reward": {"variables": {"v": {"reward": 1}}}, "actions": actions, "crop": [0, 8, 320, 216]}))
    for source in (path, tmp_path / "converted.yaml"):
        if source.suffix == ".yaml":
            source.write_text(convert_scenario_json(path))
        scenario = load_scenario(source, FIELDS)
        assert scenario.actions == actions and scenario.crop == (0, 8, 320, 216)


def test_converter_output_reads_well(tmp_path) -> None:
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps({
        "reward": {"variables": {"score": {"reward": 10.0}, "lives": {"penalty": 100.0}, "odd name": {"reward": 1.0}}},
        "done": {"condition": "all", "variables": {"lives": {"op": "zero"}, "frame": {"op": "greater-than", "reference": 99}}},
    }))
    assert convert_scenario_json(path) == (
        "# Converted from Gym Retro's scenario.json by retrokit; see retrokit docs scenarios.\n"
        "reward: 10.0 * max(delta(score), 0) + 100.0 * min(delta(lives), 0) + 1.0 * max(delta(`odd name`), 0)\n"
        "done: lives == 0 and `frame` > 99\n"
    )


# --- The wheel's scenario files -----------------------------------------------------------------------


def _wheel_scenarios() -> list[Path]:
    try:
        import stable_retro
    except ImportError:  # pragma: no cover
        return []
    root = Path(stable_retro.__file__).parent / "data" / "stable"
    names = ("data.json", "metadata.json")
    return sorted(p for p in root.glob("*/*.json") if p.name not in names)


def test_every_wheel_scenario_without_lua_loads() -> None:
    """All of stable-retro's scenario files convert and compile, except those needing Lua."""
    files = _wheel_scenarios()
    if not files:
        pytest.skip("stable-retro's integration data is not installed")
    loaded = lua = 0
    for path in files:
        data = json.loads(path.read_text())
        fields = list(json.loads((path.parent / "data.json").read_text())["info"])
        if "scripts" in data or "script" in data.get("reward", {}) or "script" in data.get("done", {}):
            lua += 1
            continue
        scenario = load_scenario(path, fields)
        run = scenario.start()
        zeros = dict.fromkeys(fields, 0)
        run.reset(zeros)
        run.step(zeros, 1, 1)
        loaded += 1
    assert loaded > 900 and lua < 60
