"""A bad Gym Retro scenario.json is refused with a message pointing into the JSON, with a caret."""

from __future__ import annotations

import json

import pytest

from retrokit.dsl.scenario import load_scenario
from retrokit.errors import ScenarioCompileError, ScenarioError, SkippedDataWarning

FIELDS = ["x", "y", "xpos", "lives", "zone", "act", "score", "length"]


def test_json_unknown_variable_points_into_the_json(tmp_path) -> None:
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps({"reward": {"variables": {"scroe": {"reward": 1}}}, "done": {}}, indent=2))
    with pytest.raises(ScenarioCompileError) as info:
        load_scenario(path, FIELDS)
    assert str(info.value) == (
        f"{path}:4:7: unknown variable 'scroe': the game has no such field. Did you mean 'score'?\n"
        '          "scroe": {\n'
        "          ^^^^^^^"
    )


@pytest.mark.parametrize(
    "data,message",
    [
        ({"done": {"variables": {"lives": {"op": "equals"}}}}, "unknown op 'equals'. Did you mean 'equal'?"),
        ({"done": {"variables": {"lives": {"measurement": "relative"}}}}, "unknown measurement 'relative'; use 'absolute' or 'delta'"),
        ({"done": {"condition": "some"}}, "unknown condition 'some'; use 'any' or 'all'"),
        ({"reward": {"script": "lua:f"}, "scripts": ["s.lua"]}, "Lua scripts cannot be converted"),
        ({"crops": [[0, 0, 1, 1]]}, "per-player crops are not supported"),
    ],
    ids=["op", "measurement", "condition", "script", "crops"],
)
def test_json_bad_inputs(tmp_path, data: dict, message: str) -> None:
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(data, indent=2))
    with pytest.raises(ScenarioError) as info:
        load_scenario(path, FIELDS)
    assert message in str(info.value)
    assert str(info.value).startswith(f"{path}:") and "^" in str(info.value)


@pytest.mark.parametrize(
    "data,skipped",
    [
        ({"rewrd": {}, "done": {}}, "rewrd (did you mean 'reward'?)"),
        ({"done": {"variables": {"lives": {"op": "zero", "refrence": 1}}}}, "done.variables.lives.refrence (did you mean 'reference'?)"),
        # stable-retro's own test data (tests/dummy.json), used as its tests use it: as a scenario too
        ({"info": {"Nes": {"address": 0, "type": "|u1"}}}, "info"),
    ],
    ids=["top_key", "variable_key", "stable-retro-dummy"],
)
def test_json_keys_stable_retro_ignores_are_skipped_in_one_warning(tmp_path, data: dict, skipped: str) -> None:
    # stable-retro's reader ignores keys it does not know; so does retrokit for its files, saying so in one line.
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(data, indent=2))
    with pytest.warns(SkippedDataWarning) as caught:
        load_scenario(path, FIELDS)
    (warning,) = caught
    assert str(warning.message) == f"{path}: skipped 1 key(s) no scenario.json has, as stable-retro skips them: {skipped}."
    assert "\n" not in str(warning.message)


def test_retrokits_own_yaml_scenario_keeps_refusing_unknown_keys(tmp_path) -> None:
    path = tmp_path / "scenario.yaml"
    path.write_text("reward: delta(score)\ndone: lives == 0\nrewrd: 1\n")
    with pytest.raises(ScenarioError, match="rewrd"):
        load_scenario(path, FIELDS)


def test_json_syntax_error(tmp_path) -> None:
    path = tmp_path / "scenario.json"
    path.write_text('{"done": {,}}')
    with pytest.raises(ScenarioError, match=r"scenario.json:1:11: this is not valid JSON: Expecting property name"):
        load_scenario(path, FIELDS)


def test_a_flood_of_unknown_keys_is_named_in_one_short_line(tmp_path) -> None:
    path = tmp_path / "scenario.json"
    data = {f"key{i}": i for i in range(5000)}
    data["x" * 1_000_000] = 1  # a key of a megabyte
    path.write_text(json.dumps({**data, "done": {}}))
    with pytest.warns(SkippedDataWarning) as caught:
        load_scenario(path, FIELDS)
    (warning,) = caught
    message = str(warning.message)
    assert "\n" not in message and len(message) < 2000 and message.endswith("and 4991 more.")
