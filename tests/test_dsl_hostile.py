"""Hostile scenario inputs end as located retrokit errors, never as Python's own.

Issue 13, faults 8 to 11: expressions too deep or too long for Python's
compiler or stack, literals the generated code cannot hold (``1e999``, a
5000-digit integer), files that are not UTF-8 or hold NUL bytes or YAML tags,
and rewards that overflow to inf or NaN while running.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from retrokit.dsl.codegen import MAX_NESTING
from retrokit.dsl.parser import MAX_DEPTH
from retrokit.dsl.scenario import load_scenario
from retrokit.errors import (
    InvalidArgumentError,
    ScenarioCompileError,
    ScenarioError,
    ScenarioRuntimeError,
    ScenarioSyntaxError,
)

FIELDS = ["x", "lives"]


def _nested(template: str, times: int, inner: str = "x") -> str:
    for _ in range(times):
        inner = template.format(inner)
    return inner


def _load(tmp_path: Path, data: bytes | str):
    path = tmp_path / "s.yaml"
    path.write_bytes(data if isinstance(data, bytes) else data.encode())
    return path, load_scenario(path, FIELDS)


def _step(scenario, x: int = 2) -> float:
    run = scenario.start()
    run.reset({"x": 1, "lives": 3})
    return run.step({"x": x, "lives": 3}, 1, 1)[0][0]


# --- fault 8: deep or long expressions ------------------------------------------------------

TOO_DEEP = [
    pytest.param(" + ".join(["x"] * 201), ScenarioSyntaxError, "nesting at most 100", id="sum_of_201_terms"),
    pytest.param(_nested("abs({})", 300), ScenarioSyntaxError, "nesting at most 100", id="300_nested_abs"),
    pytest.param("-" * 300 + "x", ScenarioSyntaxError, "nesting at most 100", id="300_unary_minus"),
    pytest.param(_nested("clip(x, 0, {})", 99), ScenarioCompileError, "brackets deep", id="99_nested_clip"),
    pytest.param(_nested("t[{}]", 99), ScenarioCompileError, "brackets deep", id="99_nested_lookups"),
    pytest.param(_nested("min(x, {})", 10_000), ScenarioSyntaxError, "nesting at most 100", id="10000_nested_min"),
    pytest.param("(" * 50_000 + "x" + ")" * 50_000, ScenarioSyntaxError, "brackets at most 1000", id="50000_parentheses"),
]


@pytest.mark.parametrize("expression,error,message", TOO_DEEP)
def test_too_deep_expression_is_a_located_error(tmp_path, expression: str, error: type, message: str) -> None:
    text = f"tables:\n  t: {{values: {{1: 2}}}}\nreward: {expression}\n"
    with pytest.raises(error, match=message) as info:
        _load(tmp_path, text)
    assert info.value.file == str(tmp_path / "s.yaml") and info.value.line == 3  # type: ignore[attr-defined]
    assert "define:" in str(info.value)  # says how to fix it


@pytest.mark.parametrize(
    "expression,value",
    [
        pytest.param(" + ".join(["x"] * MAX_DEPTH), 2.0 * MAX_DEPTH, id="sum_at_the_limit"),
        pytest.param(_nested("abs({})", MAX_DEPTH - 1), 2.0, id="nested_abs_at_the_limit"),
        pytest.param("(" * 150 + "x" + ")" * 150, 2.0, id="150_redundant_parentheses"),
        pytest.param(_nested("(x if {} > 0 else 0)", 40), 2.0, id="40_nested_ifs"),
    ],
)
def test_deep_expressions_within_the_limits_compile_and_run(tmp_path, expression: str, value: float) -> None:
    _, scenario = _load(tmp_path, f"reward: {expression}\n")
    assert _step(scenario) == value
    assert MAX_NESTING < 200  # CPython's own limit on brackets


@pytest.mark.parametrize("count", [200, 1000, 3000], ids=lambda c: f"{c}_definitions")
@pytest.mark.parametrize("order", ["in_order", "reversed"])
def test_long_chains_of_definitions_compile(tmp_path, count: int, order: str) -> None:
    chain = ["  d0: x"] + [f"  d{i}: d{i - 1} + 1" for i in range(1, count)]
    if order == "reversed":
        chain.reverse()
    _, scenario = _load(tmp_path, "define:\n" + "\n".join(chain) + f"\nreward: d{count - 1}\n")
    assert _step(scenario) == 2 + count - 1


def test_deep_analysis_leaves_the_recursion_limit_alone(tmp_path) -> None:
    limit = sys.getrecursionlimit()
    _load(tmp_path, f"reward: {_nested('abs({})', MAX_DEPTH - 1)}\n")
    assert sys.getrecursionlimit() == limit


# --- faults 9 and 10: literals and files the code cannot hold --------------------------------

BAD_FILES = [
    pytest.param(b"reward: 1e999 * x\n", ScenarioSyntaxError, (1, 9), "finite decimal", id="literal_1e999"),
    pytest.param(b"reward: x + " + b"9" * 5000 + b"\n", ScenarioSyntaxError, (1, 13), "at most 64 bits", id="5000_digit_integer"),
    pytest.param(b"reward: x + 0x1" + b"0" * 16 + b"\n", ScenarioSyntaxError, (1, 13), "at most 64 bits", id="65_bit_hex"),
    pytest.param(b"reward: x\x00 + 1\n", ScenarioError, (1, 10), "control character", id="nul_byte"),
    pytest.param(b"rew\x00ard: x\n", ScenarioError, (1, 4), "control character", id="nul_byte_in_key"),
    pytest.param("reward: x  # café\n".encode("latin-1"), ScenarioError, (1, 17), "expected UTF-8", id="latin1_file"),
    pytest.param("reward: x\n".encode("utf-16"), ScenarioError, (1, 1), "expected UTF-8", id="utf16_file"),
    pytest.param(b"name: !!python/object:os.system x\nreward: x\n", ScenarioError, (1, 7), "tagged", id="python_tag"),
    pytest.param(b"name: !!binary 'zz'\nreward: x\n", ScenarioError, (1, 7), "tagged", id="binary_tag"),
    pytest.param(b"reward: !expr x\n", ScenarioError, (1, 9), "tagged", id="local_tag"),
    pytest.param(b"crop: [" + b"9" * 5000 + b", 0, 1, 1]\nreward: x\n", ScenarioError, (1, 7), "cannot be read", id="5000_digit_crop"),
    pytest.param(b"tables:\n  t:\n    values: {1: " + b"9" * 5000 + b"}\nreward: t[x]\n", ScenarioError, (3, 17), "cannot be read", id="5000_digit_table_value"),
    pytest.param(b"tables:\n  t:\n    values: {1: 2}\n    default: .inf\nreward: t[x]\n", ScenarioError, (4, 14), "finite", id="infinite_table_default"),
    pytest.param(b"tables:\n  t:\n    values: {1: .nan}\nreward: t[x]\n", ScenarioError, (3, 17), "finite", id="nan_table_value"),
    pytest.param(b"tables:\n  t:\n    values: {1: 1e308 * 10}\nreward: t[x]\n", ScenarioError, (3, 17), "finite", id="overflowing_constant"),
    pytest.param(b"tables:\n  t:\n    values: {1: 0x1_0000_0000_0000_0000}\nreward: t[x]\n", ScenarioError, (3, 17), "64 bits", id="65_bit_table_value"),
    pytest.param(b"reward: " + b"[" * 5000 + b"\n", ScenarioError, (1, 1008), "not valid YAML: exceeded maximum nesting depth", id="5000_open_brackets"),
]


@pytest.mark.parametrize("data,error,place,message", BAD_FILES)
def test_bad_file_is_a_located_scenario_error(tmp_path, data: bytes, error: type, place: tuple[int, int], message: str) -> None:
    with pytest.raises(error, match=message) as info:
        _load(tmp_path, data)
    err = info.value
    assert (err.file, err.line, err.column) == (str(tmp_path / "s.yaml"), *place)  # type: ignore[attr-defined]


def _alias_bomb(key: str) -> str:
    """Ten lines standing for 10**9 values: each list holds the one above it ten times."""
    lines = ["      a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"      a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]" for i in range(1, 9)]
    return "tables:\n  t:\n    values: {1: 2}\n    description:\n" + "\n".join(lines) + f"\n{key}: *a8\nreward: x\n"


@pytest.mark.timeout(20)
@pytest.mark.parametrize("key", ["actions", "crop", "rewards"])
def test_an_alias_bomb_is_refused_quickly(tmp_path, key: str) -> None:
    with pytest.raises(ScenarioError, match="to add at most 100000 YAML values"):
        _load(tmp_path, _alias_bomb(key))


def test_aliases_that_repeat_a_little_are_fine(tmp_path) -> None:
    _, scenario = _load(tmp_path, "rewards:\n  - &r delta(x)\n  - *r\n")
    assert scenario.players == 2


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_a_huge_scenario_file_is_refused_before_it_is_read(tmp_path, suffix: str) -> None:
    path = tmp_path / f"huge{suffix}"
    with path.open("wb") as file:
        file.truncate(64 * 2**20)  # 64 MiB of NULs, sparse
    with pytest.raises(ScenarioError, match="at most 4 MiB"):
        load_scenario(path, FIELDS)


def test_an_included_file_that_is_not_utf8_is_located(tmp_path) -> None:
    (tmp_path / "inc.yaml").write_bytes("define:\n  a: x  # é\n".encode("latin-1"))
    with pytest.raises(ScenarioError, match="expected UTF-8") as info:
        _load(tmp_path, "include: [inc.yaml]\nreward: a\n")
    assert info.value.file == str(tmp_path / "inc.yaml") and info.value.line == 2  # type: ignore[attr-defined]


@pytest.mark.parametrize(
    "data,message",
    [
        pytest.param("{\"reward\": {}} \xe9".encode("latin-1"), "expected UTF-8", id="latin1_json"),
        pytest.param(b'{"reward": ' + b"9" * 5000 + b"}", "cannot be read", id="5000_digit_json"),
    ],
)
def test_bad_json_scenario_is_a_scenario_error(tmp_path, data: bytes, message: str) -> None:
    path = tmp_path / "scenario.json"
    path.write_bytes(data)
    with pytest.raises(ScenarioError, match=message):
        load_scenario(path, FIELDS)


# --- fault 11: rewards that are not finite numbers ---------------------------------------------

NON_FINITE = [
    pytest.param("x * 1e308 * 1e308", "got inf", id="overflow_to_inf"),
    pytest.param("-x * 1e308 * 1e308", "got -inf", id="overflow_to_minus_inf"),
    pytest.param("x / (x * 1e308 * 1e308 - x * 1e308 * 1e308)", "got nan", id="nan_divisor"),
]


@pytest.mark.parametrize("expression,message", NON_FINITE)
def test_non_finite_reward_is_a_located_runtime_error(tmp_path, expression: str, message: str) -> None:
    _, scenario = _load(tmp_path, f"rewards:\n  - x\n  - {expression}\n")
    with pytest.raises(ScenarioRuntimeError, match=message) as info:
        _step(scenario)
    err = info.value
    assert (err.line, err.column) == (3, 5)  # type: ignore[attr-defined]
    assert "reward of player 2" in str(err) and "^^^" in str(err)


def test_non_finite_check_also_guards_the_first_step(tmp_path) -> None:
    _, scenario = _load(tmp_path, "reward: x * 1e308 * 1e308\n")
    with pytest.raises(ScenarioRuntimeError, match="finite"):
        scenario.start().reset({"x": 1, "lives": 3})


def test_large_finite_rewards_pass(tmp_path) -> None:
    _, scenario = _load(tmp_path, "reward: x * 1e307\n")
    assert _step(scenario) == 2e307


@pytest.mark.parametrize(
    "variable,message",
    [
        pytest.param({"reward": "abc"}, "reward to be a finite number, got 'abc'", id="string_reward"),
        pytest.param({"penalty": [1]}, "penalty to be a finite number", id="list_penalty"),
        pytest.param({"reward": 1, "op": "equal", "reference": "x"}, "reference to be an integer", id="string_reference"),
        pytest.param({"reward": True}, "finite number, got True", id="bool_reward"),
    ],
)
def test_json_variable_with_a_wrong_number_is_located(tmp_path, variable: dict, message: str) -> None:
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps({"reward": {"variables": {"x": variable}}}, indent=2))
    with pytest.raises(ScenarioError, match=message) as info:
        load_scenario(path, FIELDS)
    assert info.value.file == str(path)  # type: ignore[attr-defined]


def test_json_time_reward_that_is_no_number_is_refused() -> None:
    with pytest.raises(ScenarioError, match="reward to be a finite number"):
        load_scenario({"reward": {"time": {"reward": "z"}}}, FIELDS)


@pytest.mark.parametrize(
    "data,message",
    [
        pytest.param({"reward": object()}, "expected plain values", id="object"),
        pytest.param({"reward": {1, 2}}, "tagged", id="set"),
        pytest.param({"reward": b"x"}, "tagged", id="bytes"),
    ],
)
def test_a_dict_scenario_with_values_yaml_cannot_hold_is_a_scenario_error(data: dict, message: str) -> None:
    with pytest.raises(ScenarioError, match=message):
        load_scenario(data, FIELDS)


@pytest.mark.parametrize("source", [5, None, ["reward: x"]], ids=["int", "none", "list"])
def test_a_scenario_source_that_is_no_path_or_dict_is_refused(source: object) -> None:
    with pytest.raises(InvalidArgumentError, match="Expected a scenario file's path or a scenario dict"):
        load_scenario(source, FIELDS)  # type: ignore[arg-type]


def test_a_dict_scenario_takes_numpy_values() -> None:
    scenario = load_scenario({"reward": "x", "crop": np.array([0, 0, 32, 16]), "tables": {"t": {"values": {1: np.int64(2)}}}}, FIELDS)
    assert scenario.crop == (0, 0, 32, 16)


def test_json_scenario_written_as_dict_with_nan_multiplier_is_refused() -> None:
    data = {"reward": {"variables": {"x": {"reward": float("nan")}}}}
    with pytest.raises(ScenarioError):
        load_scenario(json.loads(json.dumps(data)), FIELDS)


# --- Issue 19 section 6b: integers are 64-bit ---------------------------------------------------------


def _run(scenario, steps: int, x: int = 2) -> int:
    """Step ``scenario`` up to ``steps`` times; return the step it failed at (raising is the caller's to expect)."""
    run = scenario.start()
    run.reset({"x": x, "lives": 3})
    for i in range(1, steps + 1):
        run.step({"x": x, "lives": 3}, i, i)
    return steps


OVERFLOWS = [
    pytest.param("define:\n  t: prev(t, 3) * prev(t, 3)\nreward: t / 1\n", "got a 102-bit one", (2, 6), id="squaring"),
    pytest.param("reward: 1 << (frame * 100000000)\n", "shift count from 0 to 63", (1, 9), id="shift-by-frame"),
    pytest.param("define:\n  t: prev(t, 1) + 18446744073709551615\nreward: t / 1\n", "got a 65-bit one", (2, 6),
                 id="sum-past-2**64"),
    pytest.param("define:\n  n: -18446744073709551615 - x\nreward: n / 1\n", "64 bits", (2, 6), id="below-minus-2**63"),
    pytest.param("reward: x << (x - 3)\n", "got -1", (1, 9), id="negative-shift"),
]


@pytest.mark.timeout(20)
@pytest.mark.parametrize("text,message,place", OVERFLOWS)
def test_an_integer_past_64_bits_is_a_located_runtime_error(tmp_path, text: str, message: str, place) -> None:
    _, scenario = _load(tmp_path, text)
    with pytest.raises(ScenarioRuntimeError, match=message) as info:
        _run(scenario, 100)
    assert (info.value.line, info.value.column) == place  # type: ignore[attr-defined]


def test_the_squaring_scenario_fails_at_its_fifth_step_as_documented(tmp_path) -> None:
    _, scenario = _load(tmp_path, "define:\n  t: prev(t, 3) * prev(t, 3)\nreward: t / 1\n")
    run = scenario.start()
    run.reset({"x": 1, "lives": 3})
    for i in range(1, 5):
        run.step({"x": 1, "lives": 3}, i, i)  # 9, 81, 6561, 43046721, 1853020188851841: all fit
    with pytest.raises(ScenarioRuntimeError, match="overflowed"):
        run.step({"x": 1, "lives": 3}, 5, 5)


@pytest.mark.parametrize(
    "text,value",
    [
        pytest.param("reward: (x * 18446744073709551615) // 18446744073709551615\n", 2.0, id="wide-partial-result"),
        pytest.param("define:\n  big: x * 9223372036854775807\nreward: big / 1\n", 2.0 * 9223372036854775807,
                     id="unsigned-64-bit-value"),
        pytest.param("define:\n  t: prev(t, 1.5) * prev(t, 1.5)\nreward: t\n", 1.5**4, id="decimals-are-floats"),
        pytest.param("reward: x << 63\n", 2.0**64, id="shift-by-63"),
    ],
)
def test_values_inside_64_bits_run(tmp_path, text: str, value: float) -> None:
    _, scenario = _load(tmp_path, text)
    assert _step(scenario) == value


def test_no_step_grows_memory(tmp_path) -> None:
    """1 << (frame * 10**8) grew 12.5 MB a step; now it stops at once, in a child held to 500 MB."""
    from childproc import MAX_RSS_MB, run_child

    child = run_child(
        """
        from retrokit.dsl.scenario import load_scenario
        from retrokit.errors import ScenarioRuntimeError
        run = load_scenario({"reward": "1 << (frame * 100000000)"}, ["x"]).start()
        run.reset({"x": 0})
        try:
            for i in range(1, 200):
                run.step({"x": 0}, i, i)
        except ScenarioRuntimeError as exc:
            print("stopped", i)
        """,
        timeout=60,
    )
    assert child.stdout.strip() == "stopped 1" and child.peak_rss_mb < MAX_RSS_MB, child.describe()


def test_checks_are_made_only_where_a_value_can_leave_64_bits() -> None:
    """The speed of the DSL: Sonic's contest scenario tests one value a step, not every statement."""
    from retrokit.dsl.codegen import may_overflow
    from retrokit.dsl.parser import parse
    from retrokit.dsl.source import Snippet

    def can(text: str) -> bool:
        return may_overflow(parse(Snippet.standalone(text, "<test>", "reward")))

    assert not can("x") and not can("x if x > 1 else lives") and not can("x / 3") and not can("clip(x, 0, 9)")
    assert can("x * x") and can("-x") and can("delta(x)") and can("max(x, x + 1)") and can("x << lives")


# --- Issue 24: a scenario dict that holds itself, or nests too deep -----------------------------------------


def _self_holding() -> dict:
    data: dict = {"reward": "x", "tables": {"t": {"values": {1: 2}}}}
    data["tables"]["t"]["description"] = data
    return data


def _nested_list(depth: int) -> dict:
    deep: object = "x"
    for _ in range(depth):
        deep = [deep]
    return {"reward": "x", "crop": deep}


@pytest.mark.parametrize(
    "make,message",
    [
        pytest.param(_self_holding, "contains itself", id="dict-containing-itself"),
        pytest.param(lambda: _nested_list(5000), "nested at most 100 deep", id="nested-5000-deep"),
        pytest.param(lambda: {"reward": {"variables": {"x": {"reward": 1}}}, "scripts": _nested_list(5000)},
                     "nested at most 100 deep", id="gym-retro-dict-nested-5000-deep"),
    ],
)
def test_a_dict_scenario_that_loops_or_nests_too_deep_is_a_scenario_error(make, message: str) -> None:
    with pytest.raises(ScenarioError, match=message):
        load_scenario(make(), FIELDS)


def test_a_dict_scenario_may_share_a_value(tmp_path) -> None:
    shared = {"values": {1: 2}}
    scenario = load_scenario({"reward": "t[x] + u[x]", "tables": {"t": shared, "u": shared}}, FIELDS)
    assert _step(scenario, x=1) == 4.0


BOUNDED = """
from retrokit.dsl.scenario import scenario_from_text
from retrokit.errors import ScenarioError
shape = {shape!r}
if shape == "chain":  # 40,000 chained definitions: 0.94 MB, under the studio's 1 MiB body cap
    lines = ["define:", "  d0: x"] + [f"  d{{i}}: d{{i - 1}} + 1" for i in range(1, 40000)] + ["reward: d39999"]
else:  # one flat sum of 200,000 names: a megabyte in one expression
    lines = ["reward: " + "+".join(["x"] * 200000)]
text = "\\n".join(lines) + "\\n"
assert len(text) < 2**20
try:
    scenario_from_text(text, ["x"], source="big.yaml", name="big")
except ScenarioError as exc:
    print(str(exc).splitlines()[0])
"""


@pytest.mark.parametrize("shape, message", [
    ("chain", "big.yaml:4002:3: expected at most 4000 definitions in a scenario"),
    ("flat", "big.yaml:1:9: expected at most 50000 operators, names and numbers"),
], ids=["40000-definitions", "200000-names-in-one-sum"])
def test_a_scenario_under_the_body_cap_compiles_in_bounded_memory(shape: str, message: str) -> None:
    from childproc import run_child

    child = run_child(BOUNDED.format(shape=shape), timeout=300)
    assert child.returncode == 0 and child.stdout.startswith(message), child.describe()
    assert child.peak_rss_mb < 200, child.describe()
