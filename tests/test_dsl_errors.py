"""Every bad scenario is refused with a message naming the file, line and column, with a caret.

Compile-time checks (unknown names with did-you-mean, argument counts, types,
constant zero division, cycles, syntax, file structure) are shown by loading a
scenario file and comparing the whole message. Run-time failures are in
test_dsl_runtime_errors.py, Gym Retro scenario.json files' in test_dsl_json_errors.py.
"""

from __future__ import annotations

import pytest

from retrokit.dsl.scenario import load_scenario
from retrokit.errors import (
    ScenarioCompileError,
    ScenarioError,
    ScenarioSyntaxError,
)

FIELDS = ["x", "y", "xpos", "lives", "zone", "act", "score", "length"]

CASES = [
    pytest.param(
        'reward: delta(xpso) * 10\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:1:15: unknown field or definition 'xpso'. Did you mean 'xpos'? (in reward)\n"
        '    reward: delta(xpso) * 10\n'
        '                  ^^^^',
        id='unknown_field',
    ),
    pytest.param(
        'define:\n  progress: |\n    clip(x - initial(x), 0, 100)\n      / lenght\nreward: progress\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:4:9: unknown field or definition 'lenght'. Did you mean 'length'? (in define 'progress')\n"
        '          / lenght\n'
        '            ^^^^^^',
        id='unknown_field_in_block',
    ),
    pytest.param(
        'reward: "x + scroe"\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:1:14: unknown field or definition 'scroe'. Did you mean 'score'? (in reward)\n"
        '    reward: "x + scroe"\n'
        '                 ^^^^^',
        id='unknown_field_quoted_scalar',
    ),
    pytest.param(
        'tables:\n  level_end:\n    values: {1: 2}\nreward: levl_end[zone]\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:4:9: unknown table 'levl_end'. Did you mean 'level_end'? (in reward)\n"
        '    reward: levl_end[zone]\n'
        '            ^^^^^^^^',
        id='unknown_table',
    ),
    pytest.param(
        'tables:\n  level_end:\n    values: {1: 2}\nreward: level_end(zone)\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:4:9: 'level_end' is a table: look values up with square brackets, level_end[...] (in reward)\n"
        '    reward: level_end(zone)\n'
        '            ^^^^^^^^^',
        id='table_called_like_function',
    ),
    pytest.param(
        'reward: maximum(x, 0)\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:1:9: unknown function 'maximum'. Did you mean 'max'? (in reward)\n"
        '    reward: maximum(x, 0)\n'
        '            ^^^^^^^',
        id='unknown_function',
    ),
    pytest.param(
        'reward: max[x, 0]\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:1:9: 'max' is a function: call it with parentheses, max(a, b, ...) (in reward)\n"
        '    reward: max[x, 0]\n'
        '            ^^^',
        id='function_used_as_table',
    ),
    pytest.param(
        'reward: clip(x, 0)\n',
        ScenarioCompileError,
        '{tmp}/s.yaml:1:9: clip() takes 3 arguments, got 2: write clip(x, low, high) (in reward)\n'
        '    reward: clip(x, 0)\n'
        '            ^^^^^^^^^^',
        id='too_few_arguments',
    ),
    pytest.param(
        'reward: prev(x, 0, 1)\n',
        ScenarioCompileError,
        '{tmp}/s.yaml:1:9: prev() takes 1 or 2 arguments, got 3: write prev(x) or prev(x, value_at_reset) (in reward)\n'
        '    reward: prev(x, 0, 1)\n'
        '            ^^^^^^^^^^^^^',
        id='too_many_arguments',
    ),
    pytest.param(
        'reward: abs()\n',
        ScenarioCompileError,
        '{tmp}/s.yaml:1:9: abs() takes 1 argument, got 0: write abs(x) (in reward)\n'
        '    reward: abs()\n'
        '            ^^^^^',
        id='no_arguments',
    ),
    pytest.param(
        'reward: min(x)\n',
        ScenarioCompileError,
        '{tmp}/s.yaml:1:9: min() takes at least 2 arguments, got 1: write min(a, b, ...) (in reward)\n'
        '    reward: min(x)\n'
        '            ^^^^^^',
        id='min_needs_two',
    ),
    pytest.param(
        "tables:\n  level_end:\n    by: [zone, act]\n    values: {'0, 0': 2}\nreward: level_end[zone]\n",
        ScenarioCompileError,
        "{tmp}/s.yaml:5:9: table 'level_end' is keyed by 2 values (zone, act), got 1 (in reward)\n"
        '    reward: level_end[zone]\n'
        '            ^^^^^^^^^^^^^^^',
        id='table_key_count',
    ),
    pytest.param(
        'reward: x + (lives > 0)\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:1:14: a condition (boolean) is used where a number is needed, by '+'; to count a condition as a number, write (1 if condition else 0) (in reward)\n"
        '    reward: x + (lives > 0)\n'
        '                 ^^^^^^^^^',
        id='boolean_where_number',
    ),
    pytest.param(
        'done: lives\n',
        ScenarioCompileError,
        '{tmp}/s.yaml:1:7: done must be a condition (boolean), and this is a number; compare the number to make a condition, e.g. x != 0 (in done)\n'
        '    done: lives\n'
        '          ^^^^^',
        id='number_where_boolean',
    ),
    pytest.param(
        'done: not lives\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:1:11: a number is used where a condition (boolean) is needed, by 'not'; compare the number to make a condition, e.g. x != 0 (in done)\n"
        '    done: not lives\n'
        '              ^^^^^',
        id='number_where_boolean_not',
    ),
    pytest.param(
        'reward: x if lives else 0\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:1:14: a number is used where a condition (boolean) is needed, by the condition of 'if'; compare the number to make a condition, e.g. x != 0 (in reward)\n"
        '    reward: x if lives else 0\n'
        '                 ^^^^^',
        id='number_where_boolean_if',
    ),
    pytest.param(
        'done: lives == 0 and x\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:1:22: a number is used where a condition (boolean) is needed, by 'and'; compare the number to make a condition, e.g. x != 0 (in done)\n"
        '    done: lives == 0 and x\n'
        '                         ^',
        id='number_and_boolean_and',
    ),
    pytest.param(
        'reward: x > 10\n',
        ScenarioCompileError,
        '{tmp}/s.yaml:1:9: a reward must be a number, and this is a condition (boolean); to count a condition as a number, write (1 if condition else 0) (in reward)\n'
        '    reward: x > 10\n'
        '            ^^^^^^',
        id='reward_is_condition',
    ),
    pytest.param(
        'reward: x if lives > 0 else lives == 0\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:1:29: the two branches of 'if ... else' must both be numbers or both be conditions: this is a condition (boolean), the other a number (in reward)\n"
        '    reward: x if lives > 0 else lives == 0\n'
        '                                ^^^^^^^^^^',
        id='branches_differ',
    ),
    pytest.param(
        'done: (x > 0) == 1\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:1:18: the two sides of '==' must both be numbers or both be conditions: this is a number, the other a condition (boolean) (in done)\n"
        '    done: (x > 0) == 1\n'
        '                     ^',
        id='compare_bool_with_number',
    ),
    pytest.param(
        'reward: (x / 2) & 1\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:1:10: '&' needs integers, and this is a decimal number (made by '/' or a decimal literal) (in reward)\n"
        '    reward: (x / 2) & 1\n'
        '             ^^^^^',
        id='bit_op_on_decimal',
    ),
    pytest.param(
        'define:\n  seen: prev(seen, false) + 1\nreward: seen\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:2:9: a condition (boolean) is used where a number is needed, by '+'; to count a condition as a number, write (1 if condition else 0) (in define 'seen')\n"
        '      seen: prev(seen, false) + 1\n'
        '            ^^^^^^^^^^^^^^^^^',
        id='prev_default_type',
    ),
    pytest.param(
        'reward: x / 0\n',
        ScenarioCompileError,
        '{tmp}/s.yaml:1:13: division by zero: the divisor is the constant 0 (in reward)\n'
        '    reward: x / 0\n'
        '                ^',
        id='division_by_literal_zero',
    ),
    pytest.param(
        'reward: x % 0x0\n',
        ScenarioCompileError,
        '{tmp}/s.yaml:1:13: remainder by zero: the divisor is the constant 0 (in reward)\n'
        '    reward: x % 0x0\n'
        '                ^^^',
        id='modulo_by_hex_zero',
    ),
    pytest.param(
        'reward: x // (2 - 2)\n',
        ScenarioCompileError,
        '{tmp}/s.yaml:1:15: floor division by zero: the divisor is the constant 0 (in reward)\n'
        '    reward: x // (2 - 2)\n'
        '                  ^^^^^',
        id='division_by_constant_zero',
    ),
    pytest.param(
        'done: lives = 0\n',
        ScenarioSyntaxError,
        "{tmp}/s.yaml:1:13: unexpected '='; expected an operator, '(', ')', ',', '[', ']', 'else' (to compare, write '==') (in done)\n"
        '    done: lives = 0\n'
        '                ^',
        id='syntax_assignment',
    ),
    pytest.param(
        'reward: (x + 1\n',
        ScenarioSyntaxError,
        "{tmp}/s.yaml:1:15: the expression ends too early; expected ')' (in reward)\n"
        '    reward: (x + 1\n'
        '                  ^',
        id='syntax_unclosed',
    ),
    pytest.param(
        'done: lives > 0 && x > 0\n',
        ScenarioSyntaxError,
        "{tmp}/s.yaml:1:18: unexpected '&'; expected '(', '-', 'false', 'true', a name, a number (in done)\n"
        '    done: lives > 0 && x > 0\n'
        '                     ^',
        id='syntax_double_ampersand',
    ),
    pytest.param(
        'reward: x + 010\n',
        ScenarioSyntaxError,
        '{tmp}/s.yaml:1:13: the number 010 has a leading zero; write 10 (decimal) or 0x10 (hex) (in reward)\n'
        '    reward: x + 010\n'
        '                ^^^',
        id='syntax_leading_zero',
    ),
    pytest.param(
        'reward: x.__class__\n',
        ScenarioSyntaxError,
        "{tmp}/s.yaml:1:10: unexpected '.'; expected an operator, '(', ')', ',', '[', ']', 'else' (in reward)\n"
        '    reward: x.__class__\n'
        '             ^',
        id='syntax_attribute',
    ),
    pytest.param(
        "reward: __import__('os')\n",
        ScenarioSyntaxError,
        '{tmp}/s.yaml:1:20: unexpected "\'"; expected \'(\', \')\', \'-\', a name, a number (names with odd characters are written in backquotes: `my field`) (in reward)\n'
        "    reward: __import__('os')\n"
        '                       ^',
        id='syntax_string',
    ),
    pytest.param(
        "reward: ''\n",
        ScenarioSyntaxError,
        '{tmp}/s.yaml:1:9: the expression is empty (in reward)\n'
        "    reward: ''\n"
        '            ^',
        id='syntax_empty',
    ),
    pytest.param(
        'define:\n  a: b + 1\n  b: a * 2\nreward: a\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:2:6: 'a' depends on itself: a -> b -> a. A definition can use its own earlier value only through prev(name, value_at_reset), e.g. prev(a, 0) (in define 'a')\n"
        '      a: b + 1\n'
        '         ^',
        id='cycle',
    ),
    pytest.param(
        'define:\n  total: prev(total) + x\nreward: total\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:2:10: 'total' depends on itself: total -> prev(total) -> total. A definition can use its own earlier value only through prev(name, value_at_reset), e.g. prev(total, 0) (in define 'total')\n"
        '      total: prev(total) + x\n'
        '             ^^^^^^^^^^^',
        id='self_reference_without_default',
    ),
    pytest.param(
        'define:\n  x: 1\nreward: x\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:2:3: 'x' is already a field of this game; choose another name for the definition (in define 'x')\n"
        '      x: 1\n'
        '      ^',
        id='definition_shadows_field',
    ),
    pytest.param(
        'define:\n  frame: 1\nreward: frame\n',
        ScenarioCompileError,
        "{tmp}/s.yaml:2:3: 'frame' is a reserved word; choose another name (in define 'frame')\n"
        '      frame: 1\n'
        '      ^^^^^',
        id='definition_reserved',
    ),
    pytest.param(
        'rewad: x\n',
        ScenarioError,
        "{tmp}/s.yaml:1:1: unknown key 'rewad' in a scenario. Did you mean 'reward'? Known keys: name, description, include, tables, define, reward, rewards, done, dones, actions, crop, jump, reset_ram\n"
        '    rewad: x\n'
        '    ^^^^^',
        id='unknown_top_key',
    ),
    pytest.param(
        'reward: x\nrewards: [x, x]\n',
        ScenarioError,
        "{tmp}/s.yaml:2:1: give either 'reward' (one player) or 'rewards' (a list, one per player), not both\n"
        '    rewards: [x, x]\n'
        '    ^^^^^^^',
        id='reward_and_rewards',
    ),
    pytest.param(
        'define:\n  a: 1\n  a: 2\nreward: a\n',
        ScenarioError,
        "{tmp}/s.yaml:3:3: 'a' is given twice in define (first on line 2)\n"
        '      a: 2\n'
        '      ^',
        id='duplicate_key',
    ),
    pytest.param(
        'tables:\n  t:\n    values:\n      zone=0: 1\nreward: t[0]\n',
        ScenarioError,
        "{tmp}/s.yaml:4:7: a table key is one or more numbers separated by commas, e.g. '0, 1'; got 'zone=0'\n"
        '          zone=0: 1\n'
        '          ^^^^^^',
        id='bad_table_key',
    ),
    pytest.param(
        'tables:\n  t:\n    values:\n      0: x + 1\nreward: t[0]\n',
        ScenarioError,
        "{tmp}/s.yaml:4:10: the value of table 't' at 0 must be a number or a constant arithmetic expression\n"
        '          0: x + 1\n'
        '             ^^^^^',
        id='table_values_not_constant',
    ),
    pytest.param(
        'tables:\n  t:\n    values:\n      0: 1\n      1, 2: 3\nreward: t[0]\n',
        ScenarioError,
        "{tmp}/s.yaml:5:7: table 't' is keyed by 1 value, and this key has 2\n"
        '          1, 2: 3\n'
        '          ^^^^',
        id='table_arity_mixed',
    ),
    pytest.param(
        'reward: x\ncrop: [0, 0, 320]\n',
        ScenarioError,
        '{tmp}/s.yaml:2:7: crop is [x, y, width, height], four whole numbers of pixels\n'
        '    crop: [0, 0, 320]\n'
        '          ^^^^^^^^^^^',
        id='bad_crop',
    ),
    pytest.param(
        'reward: [x, y]\n',
        ScenarioError,
        '{tmp}/s.yaml:1:9: reward must be an expression (text), not a list\n'
        '    reward: [x, y]\n'
        '            ^^^^^^',
        id='expression_not_text',
    ),
    pytest.param(
        'reward: x\n  done: y\n',
        ScenarioError,
        '{tmp}/s.yaml:2:7: this is not valid YAML: mapping values are not allowed in this context\n'
        '      done: y\n'
        '          ^',
        id='invalid_yaml',
    ),
    pytest.param(
        'include: [nope.yaml]\nreward: x\n',
        ScenarioError,
        "{tmp}/s.yaml:1:11: no file 'nope.yaml' to include (looked for {tmp}/nope.yaml)\n"
        '    include: [nope.yaml]\n'
        '              ^^^^^^^^^',
        id='missing_include',
    ),
    pytest.param(
        'include: [lib.yaml]\ndefine:\n  a: 2\nreward: a\n',
        ScenarioError,
        "{tmp}/s.yaml:3:3: 'a' is already defined, at {tmp}/lib.yaml:2:3\n"
        '      a: 2\n'
        '      ^',
        id='include_redefines',
    ),
    pytest.param(
        'include: [bad.yaml]\nreward: 1\n',
        ScenarioError,
        "{tmp}/bad.yaml:1:1: unknown key 'reward' in an included file. Known keys: description, include, tables, define\n"
        '    reward: 1\n'
        '    ^^^^^^',
        id='include_with_reward',
    ),]


@pytest.mark.parametrize("text,error,message", CASES)
def test_bad_scenario_file(tmp_path, text: str, error: type[ScenarioError], message: str) -> None:
    (tmp_path / "lib.yaml").write_text("define:\n  a: 1\n")
    (tmp_path / "bad.yaml").write_text("reward: 1\n")
    path = tmp_path / "s.yaml"
    path.write_text(text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path, FIELDS)
    assert type(info.value) is error
    assert str(info.value) == message.replace("{tmp}", str(tmp_path))


def test_errors_carry_file_line_and_column(tmp_path) -> None:
    path = tmp_path / "s.yaml"
    path.write_text("# a comment\ndone: >\n  lives == 0\n  or scroe > 10\n")
    with pytest.raises(ScenarioCompileError) as info:
        load_scenario(path, FIELDS)
    err = info.value
    assert (err.file, err.line, err.column) == (str(path), 4, 6)
    assert str(err).endswith("      or scroe > 10\n         ^^^^^")


def test_error_in_a_dict_scenario_points_into_its_yaml_form() -> None:
    with pytest.raises(ScenarioCompileError) as info:
        load_scenario({"define": {"p": "x + 1"}, "reward": "p * lifes"}, FIELDS, name="mine")
    assert str(info.value) == (
        "<scenario 'mine'>:3:13: unknown field or definition 'lifes'. Did you mean 'lives'? (in reward)\n"
        "    reward: p * lifes\n"
        "                ^^^^^"
    )


def test_lark_visit_errors_are_unwrapped() -> None:
    """The leading-zero check runs inside lark's Transformer; the error comes out as ours."""
    with pytest.raises(ScenarioSyntaxError) as info:
        load_scenario({"reward": "x + 007"}, FIELDS, name="t")
    assert "lark" not in type(info.value).__module__
    assert info.value.__cause__ is None and "leading zero" in str(info.value)


def test_unknown_name_without_close_match_lists_no_suggestion() -> None:
    with pytest.raises(ScenarioCompileError, match=r"unknown field or definition 'qqq'\. \(in reward\)"):
        load_scenario({"reward": "qqq"}, FIELDS, name="t")


def test_not_a_scenario_file(tmp_path) -> None:
    with pytest.raises(ScenarioError, match=r"a \.yaml file \(retrokit\) or a \.json file \(Gym Retro\); got '\.txt'"):
        load_scenario(tmp_path / "s.txt", FIELDS)
    with pytest.raises(ScenarioError, match="Expected a scenario file at .*missing.yaml.; found No such file"):
        load_scenario(tmp_path / "missing.yaml", FIELDS)
