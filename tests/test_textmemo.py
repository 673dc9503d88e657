"""Data files read again are parsed and checked once per text: an edit shows at once, and nothing leaks between callers."""

from __future__ import annotations

import threading
from pathlib import Path

import pytest
import yaml

import retrokit
from retrokit.data import schema, yamlfile
from retrokit.data.textmemo import MAX_TEXT_CHARS, TextMemo

DASHER = Path(__file__).resolve().parent.parent / "games" / "Dasher-Genesis"


def counted(memo: TextMemo[int]) -> tuple[list[str], object]:
    calls: list[str] = []

    def get(text: str, extra: object = None) -> int:
        return memo.get(text, extra, lambda: calls.append(text) or len(calls))

    return calls, get


def test_one_computation_per_text_and_extra() -> None:
    calls, get = counted(TextMemo())
    assert get("a") == get("a") == 1
    assert get("b") == 2 and get("a", "other kind") == 3 and get("a") == 1
    assert calls == ["a", "b", "a"]


def test_the_oldest_answer_goes_first_when_full() -> None:
    calls, get = counted(TextMemo(size=2))
    get("a"), get("b"), get("c")  # "a" is dropped
    get("c"), get("b"), get("a")
    assert calls == ["a", "b", "c", "a"]


def test_a_failure_is_kept_for_nobody() -> None:
    memo: TextMemo[int] = TextMemo()
    attempts = []

    def failing() -> int:
        attempts.append(1)
        raise ValueError("bad text")

    for _ in range(2):
        with pytest.raises(ValueError, match="bad text"):
            memo.get("x", None, failing)
    assert len(attempts) == 2


def test_a_text_over_the_limit_is_computed_each_time_and_not_kept() -> None:
    calls, get = counted(TextMemo())
    big = "x" * (MAX_TEXT_CHARS + 1)
    get(big), get(big)
    assert len(calls) == 2


def test_threads_asking_at_once_all_get_the_answer() -> None:
    memo: TextMemo[str] = TextMemo(size=4)
    answers: list[str] = []

    def ask(i: int) -> None:
        for j in range(200):
            text = f"text {(i + j) % 7}"
            answers.append(memo.get(text, None, lambda text=text: text.upper()))

    threads = [threading.Thread(target=ask, args=(i,)) for i in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(answers) == 800 and all(a.startswith("TEXT ") for a in answers)


def test_load_yaml_gives_each_caller_its_own_copy() -> None:
    text = (DASHER / "game.yaml").read_text()
    first = yamlfile.load_yaml(text)
    first["fields"].clear()  # a caller changing what it was given
    second = yamlfile.load_yaml(text)
    assert second["fields"] and second == yaml.safe_load(text)


def test_load_yaml_refuses_a_duplicate_key_every_time() -> None:
    for _ in range(2):
        with pytest.raises(yamlfile.DuplicateKeyError, match="found the key 'a' twice"):
            yamlfile.load_yaml("a: 1\na: 2\n")


def test_check_text_names_each_file_its_issues_come_from() -> None:
    text = "players: many\n"
    issues = {name: schema.check_text(text, "game", name) for name in ("one/game.yaml", "two/game.yaml")}
    assert {issue.file for issue in issues["one/game.yaml"]} == {"one/game.yaml"}
    assert {issue.file for issue in issues["two/game.yaml"]} == {"two/game.yaml"}


def test_an_edited_game_yaml_shows_at_the_next_make(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    game = tmp_path / "Dasher-Genesis"
    game.mkdir()
    for name in ("game.yaml", "rom.md", "scenario.yaml", "Zone1.Act1.state"):
        (game / name).write_bytes((DASHER / name).read_bytes())
    monkeypatch.setenv("RETROKIT_GAMES", str(tmp_path))
    env = retrokit.make(str(game))
    env.reset(seed=0)
    _, _, _, _, info = env.step(env.action_space.sample())
    env.close()
    assert "p1_x" in info and "runner_x" not in info
    text = (game / "game.yaml").read_text()
    (game / "game.yaml").write_text(text.replace("  p1_x:", '  runner_x: {address: 0xFF0020, type: ">i2"}\n  p1_x:', 1))
    env = retrokit.make(str(game))
    env.reset(seed=0)
    _, _, _, _, info = env.step(env.action_space.sample())
    env.close()
    assert info["runner_x"] == info["p1_x"]
