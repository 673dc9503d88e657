"""Per-player done conditions (``dones:``) in the scenario language."""

from __future__ import annotations

import pytest

from retrokit.dsl.scenario import load_scenario
from retrokit.errors import ScenarioCompileError, ScenarioError

FIELDS = ["a_lives", "b_lives", "mode"]
TWO = "rewards:\n  - a_lives\n  - b_lives\n"


def _steps(text: str, tmp_path, *values: tuple[int, int, int]) -> list[tuple[bool, list[bool]]]:
    path = tmp_path / "s.yaml"
    path.write_text(text)
    run = load_scenario(path, FIELDS).start()
    out = []
    for i, (a, b, mode) in enumerate(values):
        fields = {"a_lives": a, "b_lives": b, "mode": mode}
        if i == 0:
            run.reset(fields)
        else:
            _, done = run.step(fields, i, i)
            out.append((done, list(run.dones)))
    return out


def test_each_player_has_its_own_done(tmp_path) -> None:
    text = TWO + "done: mode == 3\ndones:\n  - a_lives == 0\n  - b_lives == 0\n"
    assert _steps(text, tmp_path, (3, 3, 0), (3, 0, 0), (3, 0, 3)) == [
        (False, [False, True]),  # b is out, the episode goes on
        (True, [False, True]),  # the scenario's done ends it
    ]


@pytest.mark.parametrize("with_done", [True, False], ids=["with_done", "without_done"])
def test_the_episode_ends_once_every_player_is_out(tmp_path, with_done: bool) -> None:
    text = TWO + ("done: mode == 3\n" if with_done else "") + "dones: [a_lives == 0, b_lives == 0]\n"
    assert _steps(text, tmp_path, (3, 3, 0), (0, 3, 0), (0, 0, 0)) == [(False, [True, False]), (True, [True, True])]


def test_without_dones_no_player_is_ever_out(tmp_path) -> None:
    assert _steps(TWO + "done: mode == 3\n", tmp_path, (3, 3, 0), (0, 0, 0)) == [(False, [False, False])]


@pytest.mark.parametrize(
    "text,error,message,line",
    [
        pytest.param(TWO + "dones: [a_lives == 0]\n", ScenarioError, r"one done condition per player \(2", 4, id="too_few"),
        pytest.param("reward: a_lives\ndones: [a_lives == 0, b_lives == 0]\n", ScenarioError, r"per player \(1", 2, id="too_many"),
        pytest.param(TWO + "dones: [a_lives, b_lives == 0]\n", ScenarioCompileError, "must be a condition", 4, id="number"),
        pytest.param(TWO + "dones: [a_livs == 0, b_lives == 0]\n", ScenarioCompileError, "Did you mean 'a_lives'", 4, id="typo"),
        pytest.param(TWO + "dones: a_lives == 0\n", ScenarioError, "non-empty list", 4, id="not_a_list"),
    ],
)
def test_bad_dones_are_located_errors(tmp_path, text: str, error: type, message: str, line: int) -> None:
    path = tmp_path / "s.yaml"
    path.write_text(text)
    with pytest.raises(error, match=message) as info:
        load_scenario(path, FIELDS)
    assert info.value.line == line  # type: ignore[attr-defined]
