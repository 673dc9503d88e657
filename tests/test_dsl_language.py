"""What scenario expressions compute: operators, built-ins, memory, tables, players."""

from __future__ import annotations

import math

import pytest

from retrokit.dsl.scenario import load_scenario
from retrokit.errors import InvalidArgumentError

FIELDS = ["x", "y", "lives", "score", "zone", "act", "flags", "odd name", "frame"]
RAM = {"x": 7, "y": -3, "lives": 3, "score": 1200, "zone": 1, "act": 0, "flags": 0b1010, "odd name": 5, "frame": 99}


def value_of(expression: str, ram: dict | None = None, *, frame: int = 40, step: int = 10, **extra) -> object:
    """The value of ``expression`` at the first step after a reset to ``ram``."""
    kind = "done" if extra.pop("condition", False) else "reward"
    scenario = load_scenario({kind: expression, **extra}, FIELDS, name="t")
    run = scenario.start()
    values = dict(RAM, **(ram or {}))
    run.reset(values)
    rewards, done = run.step(values, frame, step)
    return done if kind == "done" else rewards[0]


@pytest.mark.parametrize(
    "expression,expected",
    [
        ("1 + 2 * 3", 7),
        ("(1 + 2) * 3", 9),
        ("10 - 4 - 3", 3),
        ("7 / 2", 3.5),
        ("7 // 2", 3),
        ("-7 // 2", -4),
        ("-7 % 3", 2),
        ("7 % -3", -2),
        ("-x", -7),
        ("- -x", 7),
        ("+x", 7),
        ("2 * -y", 6),
        ("0x10 + 0XfF", 271),
        ("1_000", 1000),
        ("1.5 * 2", 3.0),
        ("1e3", 1000.0),
        (".5 + 0.25", 0.75),
        ("flags & 2", 2),
        ("flags | 1", 11),
        ("flags ^ 0xF", 5),
        ("~flags", -11),
        ("1 << 4", 16),
        ("flags >> 1", 5),
        ("1 + 2 << 1", 6),
        ("3 if flags & 3 == 2 else 0", 3),
        ("abs(y)", 3),
        ("abs(-2.5)", 2.5),
        ("min(x, y, 0)", -3),
        ("max(x, y)", 7),
        ("max(1, 2.5)", 2.5),
        ("clip(x, 0, 5)", 5),
        ("clip(y, 0, 5)", 0),
        ("clip(3, 0, 5)", 3),
        ("clip(x, 9, 0)", 9),  # Lua's order: below low gives low,
        ("clip(x, 5, 0)", 0),  # else above high gives high
        ("sign(y)", -1),
        ("sign(x - 7)", 0),
        ("sign(0.5)", 1),
        ("frame", 40),
        ("step", 10),
        ("`frame`", 99),  # a field shadowed by the counter, in backquotes
        ("`odd name` * 2", 10),
        ("x if lives > 2 else y", 7),
        ("x if lives > 5 else y if lives > 2 else 0", -3),
        ("1 if 0 < x <= 7 else 0", 1),
        ("1 if 0 < x < 7 else 0", 0),
        ("1 if lives == 3 and not score < 1000 else 0", 1),
        ("1 if lives != 3 or true else 0", 1),
        ("1 if (x > 0) == (y > 0) else 0", 0),
        ("1 if not false and not (x > 0) else 0", 0),
    ],
    ids=lambda v: v if isinstance(v, str) else None,
)
def test_expression_values(expression: str, expected: object) -> None:
    value = value_of(expression)
    assert value == expected and isinstance(value, float)


@pytest.mark.parametrize(
    "expression,expected",
    [
        ("lives == 3", True),
        ("lives == 0 or score > 1000", True),
        ("x > 0 and y > 0", False),
        ("not (x > 0)", False),
        ("true", True),
        ("false", False),
        ("(lives < 3) == false", True),
    ],
    ids=lambda v: v if isinstance(v, str) else None,
)
def test_conditions(expression: str, expected: bool) -> None:
    assert value_of(expression, condition=True) is expected


def test_short_circuit_keeps_unreached_lookups_from_failing() -> None:
    tables = {"end": {"by": ["zone"], "values": {0: 10}}}
    assert value_of("true or x > end[zone]", condition=True, tables=tables) is True
    assert value_of("x if true else end[zone]", tables=tables) == 7


def test_comments_and_line_breaks_inside_block_expressions() -> None:
    expression = "x   # Sonic's x\n  + y  # and y\n"
    assert value_of(expression) == 4


# --- Memory ------------------------------------------------------------------------------------


def run_steps(spec: dict, reset: dict, steps: list[dict], fields=("x", "lives"), *, do_reset: bool = True) -> list:
    scenario = load_scenario(spec, list(fields), name="t")
    run = scenario.start()
    if do_reset:
        run.reset(reset)
    return [run.step(values, 4 * i, i) for i, values in enumerate(steps, 1)]


def rewards_of(expression: str, xs: list[int], x0: int = 100, **extra) -> list[float]:
    results = run_steps({"reward": expression, **extra}, {"x": x0, "lives": 3}, [{"x": x, "lives": 3} for x in xs])
    return [r[0][0] for r in results]


@pytest.mark.parametrize(
    "expression,expected",
    [
        ("prev(x)", [100, 110, 90, 130]),
        ("prev(x, -1)", [100, 110, 90, 130]),  # the default stands in at reset only
        ("delta(x)", [10, -20, 40, -10]),
        ("delta(x, 0)", [10, -20, 40, -10]),
        ("initial(x)", [100, 100, 100, 100]),
        ("peak(x)", [110, 110, 130, 130]),
        ("peak(x - initial(x))", [10, 10, 30, 30]),
        ("prev(prev(x))", [100, 100, 110, 90]),
        ("delta(delta(x))", [10, -30, 60, -50]),
        ("1 if prev(x > 100, false) else 0", [0, 1, 0, 1]),
    ],
    ids=lambda v: v if isinstance(v, str) else None,
)
def test_memory(expression: str, expected: list[int]) -> None:
    """Reset at x=100, then steps at 110, 90, 130, 120."""
    assert rewards_of(expression, [110, 90, 130, 120]) == expected


def test_definitions_refer_to_each_other_in_any_order() -> None:
    spec = {"define": {"b": "a * 2", "a": "x - initial(x)", "c": "b + a"}, "reward": "c"}
    assert [r[0][0] for r in run_steps(spec, {"x": 10, "lives": 3}, [{"x": 13, "lives": 3}])] == [9]


def test_a_definition_accumulates_through_its_own_prev() -> None:
    spec = {"define": {"total": "prev(total, 0) + x"}, "reward": "total"}
    steps = [{"x": v, "lives": 3} for v in (1, 2, 3)]
    assert [r[0][0] for r in run_steps(spec, {"x": 100, "lives": 3}, steps)] == [101, 103, 106]


def test_prev_default_stands_in_at_reset() -> None:
    """Reset is evaluated like a step with no past: prev(n, 0) is 0 there, so n counts evaluations."""
    spec = {"define": {"n": "prev(n, 0) + 1"}, "reward": "n"}
    assert [r[0][0] for r in run_steps(spec, {"x": 0, "lives": 3}, [{"x": 0, "lives": 3}] * 3)] == [2, 3, 4]


def test_stepping_without_reset_makes_the_first_step_the_reset_point() -> None:
    spec = {"reward": "x - initial(x) + delta(x)"}
    results = run_steps(spec, {}, [{"x": 5, "lives": 3}, {"x": 8, "lives": 3}], do_reset=False)
    assert [r[0][0] for r in results] == [0, 6]


def test_reset_starts_a_new_episode() -> None:
    scenario = load_scenario({"reward": "peak(x) - initial(x)"}, ["x"], name="t")
    run = scenario.start()
    run.reset({"x": 0})
    assert run.step({"x": 50}, 4, 1)[0] == (50.0,)
    run.reset({"x": 10})
    assert run.step({"x": 20}, 4, 1)[0] == (10.0,)


def test_runs_of_one_scenario_are_independent() -> None:
    scenario = load_scenario({"reward": "delta(x)"}, ["x"], name="t")
    a, b = scenario.start(), scenario.start()
    a.reset({"x": 0})
    b.reset({"x": 100})
    assert a.step({"x": 5}, 4, 1)[0] == (5.0,)
    assert b.step({"x": 5}, 4, 1)[0] == (-95.0,)
    assert a.step({"x": 6}, 8, 2)[0] == (1.0,)


def test_reset_runs_the_expressions_once_like_gym_retro() -> None:
    """prev(x, d) is d at reset, so at the first step it is the reset's value of x."""
    assert rewards_of("prev(x, 0)", [1, 2], x0=42) == [42, 1]


# --- Tables, players, outputs ----------------------------------------------------------------------


TABLES = {
    "level_end": {"by": ["zone", "act"], "values": {"0, 0": 0x100, "1, 0": "0x3080 + 0x1049", "1, 1": 7.5}},
    "bonus": {"default": -1, "values": {1: 10, 2: 20}},
}


@pytest.mark.parametrize(
    "expression,ram,expected",
    [
        ("level_end[zone, act]", {}, 0x3080 + 0x1049),
        ("level_end[0, 0]", {}, 0x100),
        ("level_end[zone, act + 1]", {}, 7.5),
        ("bonus[zone]", {}, 10),
        ("bonus[zone + 5]", {}, -1),
        ("bonus[level_end[0, 0] - 254]", {}, 20),
    ],
    ids=lambda v: v if isinstance(v, str) else None,
)
def test_tables(expression: str, ram: dict, expected: float) -> None:
    assert value_of(expression, ram, tables=TABLES) == expected


def test_per_player_rewards() -> None:
    scenario = load_scenario({"rewards": ["delta(x)", "-delta(x)", "lives"], "done": "lives == 0"}, ["x", "lives"], name="t")
    assert scenario.players == 3
    run = scenario.start()
    run.reset({"x": 0, "lives": 1})
    assert run.step({"x": 4, "lives": 0}, 4, 1) == ((4.0, -4.0, 0.0), True)


def test_defaults_no_reward_is_zero_and_no_done_is_never() -> None:
    scenario = load_scenario({}, ["x"], name="empty")
    run = scenario.start()
    run.reset({"x": 0})
    assert scenario.players == 1 and run.step({"x": 1}, 4, 1) == ((0.0,), False)


def test_actions_and_crop_pass_through() -> None:
    actions = [[[], ["LEFT"], ["RIGHT"]], [[], ["B"]]]
    scenario = load_scenario({"reward": "x", "actions": actions, "crop": [0, 16, 320, 200]}, ["x"], name="t")
    assert scenario.actions == actions and scenario.crop == (0, 16, 320, 200)
    plain = load_scenario({"reward": "x"}, ["x"], name="t")
    assert plain.actions is None and plain.crop is None


def test_include_adds_tables_and_definitions(tmp_path) -> None:
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "levels.yaml").write_text("tables:\n  ends:\n    values:\n      3: 30\ndefine:\n  end: ends[zone]\n")
    (tmp_path / "s.yaml").write_text("include: [lib/levels.yaml]\nreward: end - x\n")
    scenario = load_scenario(tmp_path / "s.yaml", ["x", "zone"])
    run = scenario.start()
    run.reset({"x": 0, "zone": 3})
    assert scenario.name == "s" and run.step({"x": 4, "zone": 3}, 4, 1)[0] == (26.0,)
    from_dict = load_scenario({"include": ["lib/levels.yaml"], "reward": "end"}, ["x", "zone"], game_dir=tmp_path)
    assert from_dict.fields == ("zone",)


def test_missing_field_in_values_is_an_argument_error() -> None:
    scenario = load_scenario({"reward": "x + lives"}, ["x", "lives"], name="t")
    run = scenario.start()
    with pytest.raises(InvalidArgumentError, match="reads field 'lives'.*no such key"):
        run.reset({"x": 1})


def test_generated_code_has_no_builtins_and_reads_fields_by_repr() -> None:
    scenario = load_scenario({"reward": "`__import__` + `a'b`"}, ["__import__", "a'b"], name="t")
    assert "v['__import__']" in scenario.source and """v["a'b"]""" in scenario.source
    run = scenario.start()
    run.reset({"__import__": 1, "a'b": 2})
    assert run.step({"__import__": 1, "a'b": 2}, 4, 1)[0] == (3.0,)


def test_decimal_results_are_exact_floats() -> None:
    assert value_of("x / 3") == 7 / 3
    assert math.isclose(value_of("(1 - clip(frame / 18000, 0, 1)) * 1000", frame=9000), 500.0)
