"""``retrokit benchmark new GAME`` writes a benchmark file; ``validate`` checks one; ``evaluate`` takes it (issue 44 item 4).

The protocol's split of a game's states is held to the benchmarks shipped for
our cartridges, which were split by hand the same way.
"""

from __future__ import annotations

import json

import pytest
from incli import retrokit_in_process

from retrokit.benchmark.definition import load_benchmark, read_benchmark
from retrokit.benchmark.making import split_states
from retrokit.data.games import find_game
from retrokit.envs import sonic


@pytest.mark.parametrize(("game", "benchmark"), [("Dasher-Genesis", "dasher"), ("Hopper-Nes", "hopper-nes")])
def test_the_protocols_split_is_the_shipped_benchmarks(game, benchmark):
    shipped = load_benchmark(benchmark)
    train, test, how = split_states(find_game(game).states)
    assert [f"{game}/{s}" for s in train] == [lv.name for lv in shipped.train]
    assert [f"{game}/{s}" for s in test] == [lv.name for lv in shipped.test]
    assert how == "the last state of each zone held out to test (3), the others to train (3)"


@pytest.mark.parametrize(
    ("states", "train", "test"),
    [
        (["Level1"], ["Level1"], ["Level1"]),
        (["Start", "Boss"], ["Start", "Boss"], ["Start", "Boss"]),
        (["Stage10", "Stage2", "Stage9", "Bonus"], ["Stage2", "Stage9", "Bonus"], ["Stage10"]),
        (["A1", "A1.2P", "A2", "A2.Hard"], ["A1"], ["A2"]),
    ],
    ids=["one-state", "no-zones", "numbers-sorted-as-numbers", "variants-left-out"],
)
def test_split_rules(states, train, test):
    assert split_states(states)[:2] == (train, test)


def test_benchmark_new_writes_a_file_evaluate_takes(tmp_path, monkeypatch):
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    done = retrokit_in_process(tmp_path, "benchmark", "new", "Hopper-Nes")
    assert done.returncode == 0, done.stderr
    assert done.stdout == (
        "Wrote the hopper-nes benchmark to hopper-nes.yaml: train Level1-1, Level2-1, Level3-1; test Level1-2, "
        "Level2-2, Level3-2 (the last state of each zone held out to test (3), the others to train (3)); "
        "1,000,000 timesteps a level.\n"
    )
    made = read_benchmark(tmp_path / "hopper-nes.yaml")
    shipped = load_benchmark("hopper-nes")
    assert (made.train, made.test) == (shipped.train, shipped.test) and made.budget == 1_000_000
    assert made.env == {"frameskip": sonic.FRAMESKIP, "sticky_prob": sonic.STICKY_PROB,
                        "max_episode_steps": sonic.MAX_EPISODE_STEPS, "scenario_every_frame": True}  # fmt: skip
    # nothing the user made is replaced unless asked
    again = retrokit_in_process(tmp_path, "benchmark", "new", "Hopper-Nes", "--budget", "5")
    assert again.returncode == 2 and "--force" in again.stderr and read_benchmark(tmp_path / "hopper-nes.yaml").budget == 1_000_000

    small = ["--train", "Level1-1", "--test", "Level1-2", "--budget", "40", "--max-episode-steps", "20", "--out", "small.yaml"]
    assert retrokit_in_process(tmp_path, "benchmark", "new", "Hopper-Nes", *small).returncode == 0
    checked = retrokit_in_process(tmp_path, "validate", "small.yaml")
    assert checked.returncode == 0, checked.stdout + checked.stderr
    assert checked.stdout == (
        "small.yaml: the hopper-nes benchmark, 1 level(s) to train and 1 to test, 40 timesteps a level: "
        "every level starts: ok\n"
    )
    ran = retrokit_in_process(tmp_path, "evaluate", "--benchmark", "small.yaml", "--agent", "random", "--out", "runs",
                              "--no-progress", "--workers", "1")  # fmt: skip
    assert ran.returncode == 0, ran.stderr
    episodes = [json.loads(line) for line in (tmp_path / "runs" / "episodes.jsonl").read_text().splitlines()]
    assert {e["level"] for e in episodes} == {"Hopper-Nes/Level1-2"} and sum(e["steps"] for e in episodes) <= 40
    assert max(e["steps"] for e in episodes) <= 20


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (("Hopper-Nes", "--test", "Level1-3"), "Did you mean 'Level1-2'?"),
        (("Hopper-Nes", "--train", "Level1-1,Levle2-1"), "Did you mean 'Level2-1'?"),
        (("Hopper-Nes", "--budget", "lots"), "Expected --budget as a whole number"),
        (("Hopper-Nes", "--budget", "0"), "Expected --budget from 1 to"),
        (("Hopper-Nes", "--max-episode-steps", "-4"), "Expected --max-episode-steps from 1 to"),
        (("Hopper-Nes", "--scenario", "scenari"), "Did you mean 'scenario'?"),
        (("Hoper-Nes",), "Hopper-Nes"),
        ((), "the following arguments are required: GAME"),
    ],
    ids=["unknown-test-state", "unknown-train-state", "budget-not-a-number", "budget-zero", "negative-steps",
         "unknown-scenario", "game-typo", "no-game"],
)  # fmt: skip
def test_benchmark_new_refuses_bad_input_in_one_line(tmp_path, argv, message):
    done = retrokit_in_process(tmp_path, "benchmark", "new", *argv)
    assert done.returncode == 2 and message in done.stderr, done.stderr
    assert not list(tmp_path.glob("*.yaml"))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("name: x\nbudget: 5\nlevels: {test: [Hopper-Nes/Level9]}\n", "Did you mean 'Level3-2'?"),
        ("name: x\nbudget: 5\nenv: {frameskip: 0}\nlevels: {test: [Hopper-Nes/Level1-1]}\n",
         "  FAIL: Hopper-Nes/Level1-1: Expected frameskip from 1"),
        ("name: x\nbudget: 5\nenv: {scenario: nope}\nlevels: {test: [Hopper-Nes/Level1-1]}\n", "nope"),
        ("name: [unclosed\n", "cannot be read as YAML"),
        ("a: &a [*a, *a]\n" + "b: &b [*a, *a, *a, *a, *a, *a, *a, *a]\n" * 3, "FAIL"),
        ("name: x\nbudget: 5\nlevels: {test: [Nope-Nes/Level1]}\n", "FAIL"),
        ("name: x\n" + "#" * (1 << 20) + "\n", "FAIL"),
    ],
    ids=["unknown-state", "bad-frameskip", "unknown-scenario", "not-yaml", "alias-bomb", "unknown-game", "huge"],
)
def test_validate_finds_what_is_wrong_with_a_benchmark_file(tmp_path, text, message):
    (tmp_path / "bench.yaml").write_text(text)
    done = retrokit_in_process(tmp_path, "validate", "bench.yaml")
    assert done.returncode == 1 and message in done.stdout, done.stdout + done.stderr
    assert done.stdout.startswith("bench.yaml: ")
