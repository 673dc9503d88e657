"""A scenario's run-time failures (division by zero, a missing table key) name the scenario and the expression."""

from __future__ import annotations

import pytest

from retrokit.dsl.scenario import load_scenario
from retrokit.errors import InvalidArgumentError, ScenarioRuntimeError

FIELDS = ["x", "y", "xpos", "lives", "zone", "act", "score", "length"]


def test_division_by_zero_at_run_time(tmp_path) -> None:
    path = tmp_path / "ratio.yaml"
    path.write_text("define:\n  ratio: x / (y - 2)\nreward: ratio\n")
    run = load_scenario(path, FIELDS).start()
    run.reset({"x": 1, "y": 3})
    assert run.step({"x": 4, "y": 4}, 4, 1)[0] == (2.0,)
    with pytest.raises(ScenarioRuntimeError) as info:
        run.step({"x": 4, "y": 2}, 8, 2)
    assert str(info.value) == (
        f"{path}:2:10: scenario 'ratio': division by zero: the divisor (y - 2) is 0 (in define 'ratio')\n"
        "      ratio: x / (y - 2)\n"
        "             ^^^^^^^^^^^"
    )
    assert isinstance(info.value, ArithmeticError)


@pytest.mark.parametrize("op,what", [("//", "floor division"), ("%", "remainder"), ("/", "division")])
def test_every_division_checks_its_divisor(op: str, what: str) -> None:
    run = load_scenario({"reward": f"x {op} y"}, FIELDS, name="t").start()
    with pytest.raises(ScenarioRuntimeError, match="division by zero: the divisor y is 0"):
        run.reset({"x": 1, "y": 0})


def test_decimal_zero_divisor_is_an_error_not_nan() -> None:
    run = load_scenario({"reward": "x / (y / 2)"}, FIELDS, name="t").start()
    with pytest.raises(ScenarioRuntimeError, match=r"the divisor \(y / 2\) is 0"):
        run.reset({"x": 0, "y": 0})


def test_missing_table_key_at_run_time(tmp_path) -> None:
    path = tmp_path / "levels.yaml"
    path.write_text("tables:\n  level_end:\n    by: [zone, act]\n    values:\n      0, 0: 100\nreward: level_end[zone, act] - x\n")
    run = load_scenario(path, FIELDS).start()
    run.reset({"x": 1, "zone": 0, "act": 0})
    with pytest.raises(ScenarioRuntimeError) as info:
        run.step({"x": 1, "zone": 5, "act": 2}, 4, 1)
    assert str(info.value) == (
        f"{path}:6:9: scenario 'levels': table 'level_end' has no entry for zone=5, act=2; "
        f"add one (at {path}:2:3) or give the table a default (in reward)\n"
        "    reward: level_end[zone, act] - x\n"
        "            ^^^^^^^^^^^^^^^^^^^^"
    )


def test_other_arithmetic_failures_name_the_scenario() -> None:
    run = load_scenario({"reward": "x >> y"}, FIELDS, name="shifty").start()
    with pytest.raises(ScenarioRuntimeError, match="scenario 'shifty': ValueError while computing a step: negative shift count"):
        run.reset({"x": 1, "y": -1})


def test_missing_value_is_an_argument_error() -> None:
    run = load_scenario({"reward": "x"}, FIELDS, name="t").start()
    with pytest.raises(InvalidArgumentError, match="scenario 't' reads field 'x'"):
        run.step({"y": 1}, 4, 1)
