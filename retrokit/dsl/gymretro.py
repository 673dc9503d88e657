"""Gym Retro ``scenario.json`` files: convert them to retrokit's language, or load them directly.

Gym Retro's rules (its ``src/data.cpp``), which the conversion keeps:

- A reward variable is *measured* (its change since the previous step by
  default, or its value with ``measurement: absolute``), passed through ``op``
  against ``reference`` (no op: the measure itself; comparisons give 1 or 0;
  ``sign`` gives -1, 0 or 1), then multiplied by ``reward`` if positive or by
  ``penalty`` if negative. Both default to 0, so ``{reward: 10}`` ignores
  decreases. ``time`` is the same rule applied to the constant 1, once per
  frame; here it is multiplied by the frames elapsed, ``delta(frame)``.
- A done variable is measured (its value by default, or ``measurement:
  delta``), passed through ``op``, and is true when the result is positive.
  ``condition: any`` (default) or ``all`` combines the variables and the
  nested ``nodes``; an empty ``all`` is always true, an empty ``any`` never.
- ``rewards`` is a list of per-player rewards; ``reward`` also fills player 1.

Lua ``script`` rewards cannot be converted; every Lua scenario of the
stable-retro wheel is rewritten by hand in ``games/<Game>/`` under its own
name (``docs/scenarios.md``).
"""

from __future__ import annotations

import json
import math
import os
import re
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path

import yaml

from retrokit.dsl.check import RESERVED
from retrokit.dsl.document import document_from_dict
from retrokit.dsl.source import SourceText, located, read_source
from retrokit.dsl.spec import ScenarioSpec
from retrokit.errors import ScenarioCompileError, ScenarioError, SkippedDataWarning, did_you_mean, listed

TOP_KEYS = ("reward", "rewards", "done", "actions", "crop", "crops", "scripts")
REWARD_KEYS = ("variables", "time", "script")
DONE_KEYS = ("variables", "nodes", "condition", "script")
VARIABLE_KEYS = ("op", "reference", "measurement", "reward", "penalty")
MEASUREMENTS = ("absolute", "delta")

#: Comparison ops: the DSL text comparing the measure ``m`` with the reference, and the same in Python.
COMPARISONS = {
    "equal": ("{m} == {ref}", lambda v, r: v == r),
    "negative-equal": ("{m} == {neg}", lambda v, r: v == -r),
    "not-equal": ("{m} != {ref}", lambda v, r: v != r),
    "less-than": ("{m} < {ref}", lambda v, r: v < r),
    "greater-than": ("{m} > {ref}", lambda v, r: v > r),
    "less-or-equal": ("{m} <= {ref}", lambda v, r: v <= r),
    "greater-or-equal": ("{m} >= {ref}", lambda v, r: v >= r),
    "nonzero": ("{m} != 0", lambda v, r: v != 0),
    "zero": ("{m} == 0", lambda v, r: v == 0),
    "positive": ("{m} > 0", lambda v, r: v > 0),
    "negative": ("{m} < 0", lambda v, r: v < 0),
}
OPS = ("", *COMPARISONS, "sign")

_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def is_gym_retro(data: Mapping) -> bool:
    """Whether a parsed scenario is Gym Retro's format (objects) rather than retrokit's (expressions)."""
    parts = [data.get("reward"), data.get("done"), *(data.get("rewards") or [])]
    return "scripts" in data or "crops" in data or any(isinstance(p, Mapping) for p in parts)


def _number(value: float) -> str:
    """A float as a DSL literal: ``10.0``, ``0.5``, ``-2.0``."""
    return repr(float(value))


def _int(value: object) -> int:
    return int(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else 0


def _reward_term(m: str, op: str, reference: int, spec: Mapping) -> str:
    """DSL text of one reward rule on measure ``m``: positive results times reward, negative times penalty."""
    good, bad = float(spec.get("reward", 0) or 0), float(spec.get("penalty", 0) or 0)
    if op in COMPARISONS:  # the result is 1 or 0
        test = COMPARISONS[op][0].format(m=m, ref=reference, neg=-reference)
        return f"({_number(good)} if {test} else 0)" if good else ""
    if op == "sign":
        parts = ([f"{_number(good)} if {m} > 0"] if good else []) + ([f"{_number(-bad)} if {m} < 0"] if bad else [])
        return "(" + " else ".join(parts) + " else 0)" if parts else ""
    if good == bad:
        return f"{_number(good)} * {m}" if good else ""
    parts = ([f"{_number(good)} * max({m}, 0)"] if good else []) + ([f"{_number(bad)} * min({m}, 0)"] if bad else [])
    return " + ".join(parts)


def _time_factor(op: str, reference: int, spec: Mapping) -> float:
    """The time term's reward per frame: the rule applied to the constant 1."""
    if op in COMPARISONS:
        measured = int(COMPARISONS[op][1](1, reference))
    else:  # no op, or sign: 1
        measured = 1
    return measured * float(spec.get("reward", 0) or 0)  # never negative, so penalty never applies


class _Converter:
    """Translate one parsed scenario.json; ``locate`` maps a key path to an error position."""

    def __init__(self, data: Mapping, source: SourceText | None, fields: Sequence[str] | None) -> None:
        self.data = data
        self.source = source
        self.fields = fields
        self.skipped: list[str] = []  # keys neither retrokit nor stable-retro knows, by path

    def error(self, path: Sequence[str], message: str, cls: type[ScenarioError] = ScenarioError) -> ScenarioError:
        if self.source is None:
            return cls(f"scenario.json, at {'.'.join(path) or 'the top'}: {message}")
        index = _find_key(self.source.text, path)
        return located(cls, self.source, index, index + len(path[-1]) + 2 if path else index + 1, message)

    def check_keys(self, obj: object, allowed: tuple[str, ...], path: list[str]) -> Mapping:
        if not isinstance(obj, Mapping):
            raise self.error(path, "expected an object ({...})")
        for key in obj:
            if key not in allowed:  # stable-retro's reader ignores it: skipped, and named in one warning
                key = str(key)[:60]  # a key of a megabyte names itself in 60 characters
                hint = did_you_mean(key, allowed).strip()
                self.skipped.append(".".join([*path, key]) + (f" ({hint[0].lower()}{hint[1:]})" if hint else ""))
        if "script" in obj:
            raise self.error(
                [*path, "script"],
                "Lua scripts cannot be converted; write the reward and done in retrokit's language "
                "(retrokit docs scenarios; the wheel's Lua scenarios are rewritten in games/<Game>/)",
            )
        return obj

    def convert(self) -> dict:
        data = self.check_keys(self.data, TOP_KEYS, [])
        if "scripts" in data:
            raise self.error(["scripts"], "Lua scripts cannot be converted; write the scenario in retrokit's language (retrokit docs scenarios)")
        if "crops" in data:
            raise self.error(["crops"], "per-player crops are not supported; give one 'crop'")
        players = [dict(self.check_keys(data["reward"], REWARD_KEYS, ["reward"]))] if "reward" in data else [{}]
        paths = [["reward"]]
        for i, reward in enumerate(data.get("rewards") or []):
            reward = self.check_keys(reward, REWARD_KEYS, ["rewards", str(i)])
            if i == 0:  # Gym Retro adds rewards[0] to reward: variables already set win, time is replaced
                variables = {**reward.get("variables", {}), **players[0].get("variables", {})}
                players[0] = {**players[0], **({"time": reward["time"]} if "time" in reward else {}), "variables": variables}
                paths[0] = ["reward"] if "reward" in data else ["rewards", "0"]
            else:
                players.append(dict(reward))
                paths.append(["rewards", str(i)])
        out: dict = {}
        rewards = [self.reward(spec, path) for spec, path in zip(players, paths)]
        if len(rewards) == 1:
            out["reward"] = rewards[0]
        else:
            out["rewards"] = rewards
        out["done"] = self.done(data.get("done", {}), ["done"], top=True)
        if "actions" in data:
            out["actions"] = data["actions"]
        if "crop" in data:
            out["crop"] = list(data["crop"])
        if self.skipped:
            where = self.source.name if self.source is not None else "scenario.json"
            warnings.warn(
                f"{where}: skipped {len(self.skipped)} key(s) no scenario.json has, as stable-retro skips them: "
                f"{listed(self.skipped, width=120)}.",
                SkippedDataWarning, stacklevel=2,
            )
        return out

    def check_numbers(self, spec: Mapping, path: list[str]) -> None:
        """Refuse a variable's reward or penalty that is no finite number, or a reference that is no integer."""
        for key in ("reward", "penalty", "reference"):
            value = spec.get(key)
            if value is None:
                continue
            whole = key == "reference"
            number = isinstance(value, int if whole else (int, float)) and not isinstance(value, bool)
            if not number or not math.isfinite(value):
                wanted = "an integer" if whole else "a finite number"
                raise self.error([*path, key], f"expected {key} to be {wanted}, got {value!r}")

    def measure(self, name: str, spec: Mapping, path: list[str], default: str) -> tuple[str, str, int]:
        """The DSL text of a variable's measure, its op, and its reference."""
        spec = self.check_keys(spec, VARIABLE_KEYS, path)
        self.check_numbers(spec, path)
        if self.fields is not None and name not in self.fields:
            raise self.error(path, f"unknown variable {name!r}: the game has no such field." + did_you_mean(name, self.fields), ScenarioCompileError)
        measurement = spec.get("measurement", default)
        if measurement not in MEASUREMENTS:
            raise self.error([*path, "measurement"], f"unknown measurement {measurement!r}; use 'absolute' or 'delta'")
        op = spec.get("op", "")
        if op not in OPS:
            raise self.error([*path, "op"], f"unknown op {op!r}." + did_you_mean(str(op), OPS[1:]) + f" Known ops: {', '.join(OPS[1:])}")
        ref = name if _IDENTIFIER.fullmatch(name) and name not in RESERVED else f"`{name}`"
        return (f"delta({ref})" if measurement == "delta" else ref), op, _int(spec.get("reference", 0))

    def reward(self, spec: Mapping, path: list[str]) -> str:
        terms = []
        for name, var in (spec.get("variables") or {}).items():
            m, op, reference = self.measure(name, var, [*path, "variables", name], "delta")
            terms.append(_reward_term(m, op, reference, var))
        if "time" in spec:  # the rule applied to the constant 1, each frame
            time = self.check_keys(spec["time"], VARIABLE_KEYS, [*path, "time"])
            self.check_numbers(time, [*path, "time"])
            op = time.get("op", "")
            if op not in OPS:
                raise self.error([*path, "time", "op"], f"unknown op {op!r}." + did_you_mean(str(op), OPS[1:]))
            factor = _time_factor(op, _int(time.get("reference", 0)), time)
            if factor:
                terms.append(f"{_number(factor)} * delta(frame)")
        terms = [t for t in terms if t]
        return " + ".join(terms) if terms else "0"

    def done(self, spec: Mapping, path: list[str], *, top: bool = False) -> str:
        spec = self.check_keys(spec, DONE_KEYS, path)
        tests = []
        for name, var in (spec.get("variables") or {}).items():
            m, op, reference = self.measure(name, var, [*path, "variables", name], "absolute")
            if op in COMPARISONS:
                tests.append(COMPARISONS[op][0].format(m=m, ref=reference, neg=-reference))
            else:  # no op or sign: true when the measure is positive
                tests.append(f"{m} > 0")
        for name, node in (spec.get("nodes") or {}).items():
            tests.append(f"({self.done(node, [*path, 'nodes', name])})")
        condition = spec.get("condition", "any")
        if condition not in ("any", "all"):
            raise self.error([*path, "condition"], f"unknown condition {condition!r}; use 'any' or 'all'")
        if not tests:
            return "true" if condition == "all" else "false"
        return (" and " if condition == "all" else " or ").join(tests)


def _find_key(text: str, path: Sequence[str]) -> int:
    """Index of the last key of ``path`` in JSON ``text`` (searching each key after the previous)."""
    index = 0
    for key in path:
        if key.isdigit():
            continue
        match = re.compile(re.escape(json.dumps(key)) + r"\s*:").search(text, index)
        if match is None:
            return index
        index = match.start()
    return index


def _read_json(path: Path) -> tuple[dict, SourceText]:
    source = read_source(path)
    try:
        data = json.loads(source.text)
    except json.JSONDecodeError as exc:
        raise located(ScenarioError, source, exc.pos, exc.pos + 1, f"this is not valid JSON: {exc.msg}") from None
    except (ValueError, RecursionError) as exc:  # an integer of over 4300 digits; arrays nested thousands deep
        raise located(ScenarioError, source, 0, 1, f"this JSON cannot be read: {exc}") from None
    if not isinstance(data, dict):
        raise located(ScenarioError, source, 0, 1, "a scenario.json file holds an object ({...})")
    return data, source


def convert_json_dict(data: Mapping, *, fields: Sequence[str] | None = None, source: SourceText | None = None) -> dict:
    """Convert a parsed scenario.json to a retrokit scenario dict (expressions as text)."""
    return _Converter(data, source, fields).convert()


def convert_scenario_json(path: str | os.PathLike[str]) -> str:
    """Convert a Gym Retro ``scenario.json`` file to retrokit scenario YAML text.

    Args:
        path: The ``.json`` file.

    Returns:
        The YAML text, with a header naming the source file.

    Raises:
        ScenarioError: The file is malformed, uses Lua scripts, or an unknown op.
    """
    data, source = _read_json(Path(path))
    converted = convert_json_dict(data, source=source)
    lines = [f"# Converted from Gym Retro's {Path(path).name} by retrokit; see retrokit docs scenarios."]
    for key, value in converted.items():
        if key == "rewards":
            lines += ["rewards:"] + [f"  - {_yaml_value(reward)}" for reward in value]
        else:
            lines.append(f"{key}: {_yaml_value(value)}")
    return "\n".join(lines) + "\n"


def _yaml_value(value: object) -> str:
    """One value as YAML on one line: a plain or quoted scalar, or a flow list."""
    text = yaml.safe_dump(value, default_flow_style=True, width=1_000_000)
    return text.removesuffix("\n...\n").strip()


def spec_from_json(path: str | os.PathLike[str], fields: Sequence[str], *, name: str | None = None) -> ScenarioSpec:
    """Load a Gym Retro ``scenario.json`` file directly, checking its variables against ``fields``."""
    path = Path(path)
    data, source = _read_json(path)
    converted = convert_json_dict(data, fields=fields, source=source)
    return document_from_dict(converted, name=name or path.stem)


def spec_from_json_dict(data: Mapping, fields: Sequence[str], *, name: str) -> ScenarioSpec:
    """Load an already-parsed Gym Retro scenario dict."""
    return document_from_dict(convert_json_dict(data, fields=fields), name=name)
