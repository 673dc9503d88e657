"""``retrokit evaluate`` end to end on the Dasher benchmark: files, scores, determinism, resume, bad input."""

from __future__ import annotations

import csv
import io
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from evaluating import SMALL, evaluate, session_processes, wait_for, write_agents
from PIL import Image

from retrokit.cli import main


def summary(out: Path) -> bytes:
    return (out / "summary.json").read_bytes()


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> Path:
    """JERK on two levels, 300 timesteps each, seed 0, on two workers, saving GIFs.

    JERK ends 1 episode on Zone2.Act2 and 8 on Zone3.Act2, and scores over 2.5 times random's aggregate (1016 to
    374); GIFs and the number of workers change nothing in the summary (the same-seed test shows it).
    """
    out = tmp_path_factory.mktemp("reference") / "run"
    assert evaluate(out, "--agent", "jerk", "--workers", "2", "--gif") == 0
    return out


@pytest.fixture(scope="module")
def random_run(tmp_path_factory) -> Path:
    """Random on the reference's levels and timesteps."""
    out = tmp_path_factory.mktemp("random") / "run"
    assert evaluate(out, "--agent", "random", "--workers", "2") == 0
    return out


def test_dasher_writes_every_file(reference) -> None:
    out = reference
    episodes = [json.loads(line) for line in (out / "episodes.jsonl").read_text().splitlines()]
    assert {e["level"] for e in episodes} == {"Dasher-Genesis/Zone2.Act2", "Dasher-Genesis/Zone3.Act2"}
    assert set(episodes[0]) == {"level", "episode", "steps", "reward", "timesteps", "wall"}
    data = json.loads((out / "summary.json").read_text())
    for level, entry in data["levels"].items():
        mine = [e for e in episodes if e["level"] == level]
        assert entry["episodes"] == len(mine) >= 1
        assert entry["mean_score"] == pytest.approx(sum(e["reward"] for e in mine) / len(mine))
        assert entry["timesteps"] == 300 and max(e["timesteps"] for e in mine) <= 300
    assert max(e["episodes"] for e in data["levels"].values()) >= 3  # a mean over several episodes is checked
    assert data["aggregate"] == pytest.approx(sum(e["mean_score"] for e in data["levels"].values()) / 2)
    rows = (out / "summary.csv").read_text().splitlines()
    assert rows[0].startswith("level,mean_score") and len(rows) == 4 and rows[-1].startswith("aggregate,")
    report = (out / "report.md").read_text()
    assert "| Dasher-Genesis/Zone2.Act2 |" in report and "![learning-curves](learning-curves.png)" in report
    for png in ("learning-curves.png", "scores.png"):
        with Image.open(out / png) as image:
            assert image.format == "PNG" and image.size[0] >= 600 and image.size[1] >= 250
    for level in data["levels"]:
        with Image.open(out / "gifs" / f"{level.replace('/', '_')}.gif") as gif:
            assert gif.n_frames > 10 and gif.size == (320, 224)


def test_jerk_beats_random_by_a_clear_margin(reference, random_run) -> None:
    jerk, rand = (json.loads(summary(run))["aggregate"] for run in (reference, random_run))
    assert jerk > 1.5 * rand, (jerk, rand)


@pytest.mark.parametrize("run", ["reference", "random_run"])
def test_the_final_score_averages_the_episodes_of_the_budgets_last_tenth(run, request) -> None:
    out = request.getfixturevalue(run)
    episodes = [json.loads(line) for line in (out / "episodes.jsonl").read_text().splitlines()]
    data = json.loads(summary(out))
    finals, windows = [], []
    for level, entry in data["levels"].items():
        mine = [e for e in episodes if e["level"] == level]
        # The episodes that ended in the last 30 of the 300 timesteps; with none, the last that ended.
        window = [e["reward"] for e in mine if e["timesteps"] > 270] or [mine[-1]["reward"]]
        windows.append(any(e["timesteps"] > 270 for e in mine))
        assert entry["final_score"] == pytest.approx(sum(window) / len(window)), level
        assert entry["final_episodes"] == len(window)
        finals.append(entry["final_score"])
    assert any(windows)  # a window held an episode (and, in JERK's run, one level had none: the fallback)
    assert data["final_aggregate"] == pytest.approx(sum(finals) / len(finals))
    curve = data["curve"]
    assert len(curve["timesteps"]) == 50 and curve["timesteps"][-1] == 300
    assert curve["score"][-1] == pytest.approx(data["final_aggregate"])  # Figure 3's curve ends at the final score
    rows = list(csv.DictReader(io.StringIO((out / "summary.csv").read_text())))
    assert [float(r["final_score"]) for r in rows[:-1]] == pytest.approx(finals)
    assert float(rows[-1]["final_score"]) == pytest.approx(data["final_aggregate"])
    report = (out / "report.md").read_text()
    assert "| mean score | sd | final score |" in report and f"**{data['final_aggregate']:,.1f}**" in report
    assert "![mean-learning-curve](mean-learning-curve.png)" in report
    with Image.open(out / "mean-learning-curve.png") as image:
        assert image.format == "PNG" and image.size == (640, 400)


def test_the_same_seed_gives_the_same_summary_twice_and_on_two_workers(reference, tmp_path) -> None:
    # The reference played on two workers (saving GIFs): once more on one worker, without.
    assert evaluate(tmp_path / "again", "--agent", "jerk", "--workers", "1") == 0
    assert summary(tmp_path / "again") == summary(reference)
    # Each level's seed derives from the run's seed: another seed plays the level otherwise.
    assert evaluate(tmp_path / "other", "--agent", "jerk", "--seed", "1", "--levels", "Zone3.Act2") == 0
    level = "Dasher-Genesis/Zone3.Act2"
    other, same = (json.loads(summary(run))["levels"][level] for run in (tmp_path / "other", reference))
    assert other != same and other["timesteps"] == same["timesteps"], (other, same)


def test_an_interrupted_run_resumes_to_the_uninterrupted_result(reference, agents_file, tmp_path, monkeypatch) -> None:
    # The agent is JERK, which on the second level holds still at its 200th step until a flag file
    # appears: the test interrupts it there, with the first level finished and the second half-played.
    flag = tmp_path / "go-on"
    monkeypatch.setenv("RETROKIT_TEST_FLAG", str(flag))
    out = tmp_path / "run"
    command = [sys.executable, "-m", "retrokit", "evaluate", *SMALL, "--agent", f"{agents_file}:jerk_pausing",
               "--workers", "1", "--out", str(out)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not (tmp_path / "waiting").exists() and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    assert "--resume" in err
    assert list(json.loads((out / "run.json").read_text())["finished"]) == ["Dasher-Genesis/Zone2.Act2"]
    played = (out / "episodes.jsonl").read_text()
    assert "Dasher-Genesis/Zone3.Act2" in played  # some of its episodes, to be dropped on resume
    interrupted = json.loads(summary(out))
    assert not interrupted["complete"] and list(interrupted["levels"]) == ["Dasher-Genesis/Zone2.Act2"]
    flag.touch()
    assert evaluate(out, "--agent", f"{agents_file}:jerk_pausing", "--workers", "2", "--resume") == 0
    resumed, uninterrupted = json.loads(summary(out)), json.loads(summary(reference))
    assert (resumed["levels"], resumed["aggregate"]) == (uninterrupted["levels"], uninterrupted["aggregate"])
    assert (out / "episodes.jsonl").read_text().count("\n") == sum(e["episodes"] for e in resumed["levels"].values())


def _killed_copy(reference: Path, tmp_path: Path) -> Path:
    """A copy of the reference's folder as if killed while playing its second level."""
    import shutil

    out = tmp_path / "run"
    shutil.copytree(reference, out)
    state = json.loads((out / "run.json").read_text())
    del state["finished"]["Dasher-Genesis/Zone3.Act2"]
    (out / "run.json").write_text(json.dumps(state))
    return out


def test_a_half_written_episode_line_is_dropped_on_resume(reference, tmp_path) -> None:
    out = _killed_copy(reference, tmp_path)
    with (out / "episodes.jsonl").open("a") as log:
        log.write('{"level": "Dasher-Genesis/Zone3.Act2", "epis')
    assert evaluate(out, "--agent", "jerk", "--resume") == 0
    assert summary(out) == summary(reference)


def test_resume_alone_takes_the_options_from_the_run_folder(reference, tmp_path) -> None:
    """The --help example `retrokit evaluate --out runs/mine --resume`: no option but the folder (issue 42)."""
    out = _killed_copy(reference, tmp_path)
    assert main(["evaluate", "--out", str(out), "--resume", "--no-progress"]) == 0
    assert summary(out) == summary(reference)


def test_resume_needs_the_same_settings(reference, tmp_path, capsys) -> None:
    import shutil

    out = tmp_path / "run"
    shutil.copytree(reference, out)
    assert evaluate(out, "--agent", "jerk", "--seed", "5", "--resume") == 2
    assert "seed differ" in capsys.readouterr().err
    assert evaluate(tmp_path / "none", "--agent", "jerk", "--resume") == 2
    assert "drop --resume" in capsys.readouterr().err


def test_an_earlier_evaluation_is_never_overwritten(reference, capsys) -> None:
    before = summary(reference)
    assert evaluate(reference, "--agent", "random") == 2
    assert "already holds an evaluation" in capsys.readouterr().err
    assert summary(reference) == before


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--levels", "Zone9.Act1"], "Expected a level of the dasher benchmark"),
        (["--levels", "Zone1.Act3"], "Did you mean"),
        (["--agent", "jerky"], "Did you mean 'jerk'?"),
        (["--agent", "no_such_module:agent"], "importing 'no_such_module' failed"),
        (["--agent", "retrokit.benchmark.agents:nothing"], "to define a callable 'nothing'"),
        (["--benchmark", "dashr"], "Did you mean 'dasher'?"),
        (["--workers", "0"], "Expected --workers of 1 or more, got 0."),
        (["--timesteps", "-5"], "Expected --timesteps of 1 or more, got -5."),
        (["--seed", "-1"], "Expected a --seed of 0 or more, got -1"),
        (["--stall-timeout", "0"], "Expected a --stall-timeout of more than 0 seconds"),
        (["--stall-timeout", "nan"], "Expected a --stall-timeout of more than 0 seconds"),
        (["--ray-address", "127.0.0.1:9"], "Expected --backend ray with --ray-address"),
        (["--agent", "jerk", "--agent", "jerk"], "Expected each --agent once"),
        (["--agent", "jerk", "--agent", "jerky"], "Did you mean 'jerk'?"),
    ],
    ids=["unknown-level", "level-typo", "agent-typo", "agent-module", "agent-callable", "benchmark-typo", "workers", "timesteps",
         "negative-seed", "zero-stall", "nan-stall", "ray-address-without-ray", "agent-twice", "second-agent-typo"],
)
def test_bad_names_fail_before_anything_is_written(tmp_path, capsys, args, expected) -> None:
    out = tmp_path / "run"
    assert main(["evaluate", "--timesteps", "100", "--no-progress", "--out", str(out), *args]) == 2
    err = capsys.readouterr().err
    assert expected in err and err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists()


AGENTS = '''
import numpy as np

def fails_on_zone2(env, budget, seed):
    """Plays right; raises at its 51st step on Zone2.Act2."""
    right = env.unwrapped.actions.press(["RIGHT"])
    env.reset()
    for step in range(10**9):
        if step == 50 and env.unwrapped.state_name == "Zone2.Act2":
            raise ValueError("the agent's own bug")
        _, _, terminated, truncated, _ = env.step(right)
        if terminated or truncated:
            env.reset()

def wrong_shape(env, budget, seed):
    env.reset()
    env.step(np.zeros(5, dtype=np.int8))

def out_of_range(env, budget, seed):
    env.reset()
    for _ in range(9):
        env.step(np.zeros(12, dtype=np.int8))
    env.step(np.full(12, 3, dtype=np.int8))

def jerk_pausing(env, budget, seed):
    """JERK; on Zone3.Act2 its 200th step waits for a flag file (so a test can interrupt it there)."""
    import os, pathlib, time
    import gymnasium
    from retrokit.benchmark.jerk import jerk

    flag = pathlib.Path(os.environ["RETROKIT_TEST_FLAG"])

    class Pause(gymnasium.Wrapper):
        steps = 0

        def step(self, action):
            self.steps += 1
            if self.steps == 200 and env.unwrapped.state_name == "Zone3.Act2":
                (flag.parent / "waiting").touch()
                while not flag.exists():
                    time.sleep(0.05)
            return self.env.step(action)

    jerk(Pause(env), budget, seed)

def no_reset(env, budget, seed):
    env.step(np.zeros(12, dtype=np.int8))
'''


@pytest.fixture
def agents_file(tmp_path) -> Path:
    return write_agents(tmp_path, AGENTS)


def test_an_agent_that_raises_names_level_and_step_and_keeps_the_rest(agents_file, tmp_path, capsys) -> None:
    out = tmp_path / "run"
    assert evaluate(out, "--agent", f"{agents_file}:fails_on_zone2", "--workers", "2", "--timesteps", "150") == 2
    err = capsys.readouterr().err
    assert "raised ValueError: the agent's own bug (level Dasher-Genesis/Zone2.Act2, step 51" in err
    assert "--resume" in err and "Traceback" not in err
    kept = json.loads(summary(out))
    assert list(kept["levels"]) == ["Dasher-Genesis/Zone3.Act2"] and kept["levels"]["Dasher-Genesis/Zone3.Act2"]["episodes"]
    assert "## Levels that failed" in (out / "report.md").read_text()


@pytest.mark.parametrize(
    ("agent", "expected"),
    [
        ("wrong_shape", "(level Dasher-Genesis/Zone2.Act2, step 1), got array [0,0,0,0,0] of shape (5,)"),
        ("out_of_range", "Expected an action of MultiBinary(12) (level Dasher-Genesis/Zone2.Act2, step 10)"),
        ("no_reset", "Expected reset() before step() at the start of an episode (level Dasher-Genesis/Zone2.Act2, step 1)"),
    ],
    ids=["shape", "range", "no-reset"],
)
def test_an_invalid_action_names_level_and_step(agents_file, tmp_path, capsys, agent, expected) -> None:
    assert evaluate(tmp_path / "run", "--agent", f"{agents_file}:{agent}", "--levels", "Zone2.Act2") == 2
    assert expected in capsys.readouterr().err


def test_sonic_runs_up_to_the_missing_roms(tmp_path, monkeypatch, capsys) -> None:
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "empty"))
    assert main(["evaluate", "--benchmark", "sonic", "--agent", "jerk", "--out", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err
    for game in ("SonicTheHedgehog-Genesis", "SonicTheHedgehog2-Genesis", "SonicAndKnuckles3-Genesis"):
        assert game in err
    assert "retrokit import" in err and not (tmp_path / "run").exists()


def test_sonic_lists_the_papers_split(capsys) -> None:
    assert main(["evaluate", "--benchmark", "sonic", "--list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert sum(line.startswith("test ") for line in lines) == 11
    assert sum(line.startswith("train") for line in lines) == 47


def test_a_benchmark_file_runs_and_says_what_a_built_core_would_gain(tmp_path, monkeypatch, capsys) -> None:
    from retrokit.host.buildhint import build_hint

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))  # no built core there: the wheel's runs
    path = tmp_path / "mine.yaml"
    path.write_text("name: mine\nbudget: 200\nenv: {frameskip: 4, max_episode_steps: 100}\n"
                    "levels:\n  test: [Dasher-Genesis/Zone1.Act1]\n")
    out = tmp_path / "run"
    assert main(["evaluate", "--benchmark", str(path), "--agent", "random", "--no-progress", "--out", str(out)]) == 0
    data = json.loads(summary(out))
    assert data["benchmark"] == "mine" and data["levels"]["Dasher-Genesis/Zone1.Act1"]["timesteps"] == 200
    err = capsys.readouterr().err
    assert err.splitlines().count(build_hint("Genesis")) == 1 and "retrokit build-core" in build_hint("Genesis")


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("- a\n- b\n", "holds a list, not a mapping"),
        ("budget: 0\nlevels: {test: [Dasher-Genesis/Zone1.Act1]}\n", "'budget' must be a whole number"),
        ("budget: 10\nlevels: {test: [Zone1.Act1]}\n", "as 'Game-System/State'"),
        ("budget: 10\nlevels: {train: [Dasher-Genesis/Zone1.Act1]}\n", "'levels' must map 'test'"),
        ("budget: 10\nenv: {turbo: 1}\nlevels: {test: [Dasher-Genesis/Zone1.Act1]}\n", "'env' must map options"),
        ("budget: 10\nlevelz: {}\n", "unknown keys ['levelz']"),
        ("\x00\xff\xfe garbage: [", "cannot be read as YAML"),
        ("a: " + "x" * (1 << 20), "of at most 1 MiB; found a larger file"),
    ],
    ids=["list", "budget", "level-name", "no-test", "env-option", "unknown-key", "binary", "huge"],
)
def test_malformed_benchmark_files_are_refused(tmp_path, capsys, text, expected) -> None:
    path = tmp_path / "bad.yaml"
    path.write_bytes(text.encode("latin-1"))
    assert main(["evaluate", "--benchmark", str(path), "--out", str(tmp_path / "run")]) == 2
    assert expected in capsys.readouterr().err


def test_a_missing_state_is_named(tmp_path, capsys) -> None:
    path = tmp_path / "mine.yaml"
    path.write_text("budget: 10\nlevels: {test: [Dasher-Genesis/Zone4.Act1]}\n")
    assert main(["evaluate", "--benchmark", str(path), "--out", str(tmp_path / "run")]) == 2
    assert "Dasher-Genesis/Zone4.Act1" in capsys.readouterr().err


def test_a_level_whose_env_cannot_start_fails_alone(tmp_path, capsys) -> None:
    path = tmp_path / "mine.yaml"
    path.write_text("budget: 100\nenv: {obs_type: pixels}\nlevels: {test: [Dasher-Genesis/Zone1.Act1]}\n")
    out = tmp_path / "run"
    assert main(["evaluate", "--benchmark", str(path), "--agent", "random", "--no-progress", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "Expected to start level Dasher-Genesis/Zone1.Act1 (step 0)" in err and "obs_type" in err
    assert json.loads(summary(out))["levels"] == {}


@pytest.mark.parametrize("workers", ["1", "2"])
@pytest.mark.parametrize("point", [0.2, 0.7], ids=["early", "late"])
def test_a_killed_run_resumes_to_the_uninterrupted_result(reference, tmp_path, workers, point) -> None:
    # SIGKILL once a share of the reference's episodes is logged: no handler runs, the folder is as the kill left it.
    lines = (reference / "episodes.jsonl").read_text().count("\n")
    out = tmp_path / "run"
    command = [sys.executable, "-m", "retrokit", "evaluate", *SMALL, "--agent", "jerk", "--workers", workers,
               "--out", str(out)]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
    log = out / "episodes.jsonl"
    wait_for(lambda: process.poll() is not None or (log.is_file() and log.read_text().count("\n") >= lines * point),
             120, "episodes to be logged")
    process.kill()
    process.communicate(timeout=30)
    wait_for(lambda: not session_processes(process.pid), 20, "the killed run's workers to end")
    assert evaluate(out, "--agent", "jerk", "--workers", workers, "--resume") == 0
    assert summary(out) == summary(reference)


def test_a_second_run_on_a_folder_in_use_is_refused(agents_file, tmp_path, monkeypatch, capsys) -> None:
    flag = tmp_path / "go-on"
    monkeypatch.setenv("RETROKIT_TEST_FLAG", str(flag))
    out = tmp_path / "run"
    command = [sys.executable, "-m", "retrokit", "evaluate", *SMALL, "--agent", f"{agents_file}:jerk_pausing",
               "--levels", "Zone3.Act2", "--workers", "1", "--out", str(out)]
    first = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        wait_for(lambda: (tmp_path / "waiting").exists() or first.poll() is not None, 120, "the first run to pause")
        assert evaluate(out, "--agent", f"{agents_file}:jerk_pausing", "--levels", "Zone3.Act2", "--resume") == 2
        err = capsys.readouterr().err
        assert f"Expected no other evaluation running in the folder {str(out)!r}; found one there (process {first.pid})" in err
        assert err.count("\n") == 1
        assert json.loads((out / "run.json").read_text())["finished"] == {}
    finally:
        flag.touch()
        _, err = first.communicate(timeout=120)
    assert first.returncode == 0, err


def test_help_gives_the_agents_signature_the_backend_default_and_examples(capsys) -> None:
    assert main(["evaluate", "--help"]) == 0
    text = capsys.readouterr().out
    assert "agent(env: gymnasium.Env, budget: int, seed: int) -> None" in text
    assert "(default: local; Ray is the extra retrokit-rl[ray])" in " ".join(text.split())
    examples = text[text.index("examples:"):].splitlines()[1:]
    assert len(examples) >= 5 and all(line.strip().startswith("retrokit evaluate --") for line in examples if line)


def test_ctrl_c_at_a_terminal_stops_the_workers_quietly(reference, tmp_path) -> None:
    # A terminal sends SIGINT to the whole process group: the workers leave it to the evaluation's process.
    out = tmp_path / "run"
    command = [sys.executable, "-m", "retrokit", "evaluate", *SMALL, "--agent", "jerk", "--workers", "2",
               "--out", str(out)]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)
    log = out / "episodes.jsonl"
    wait_for(lambda: process.poll() is not None or (log.is_file() and log.read_text().count("\n") >= 2),
             120, "episodes to be logged")
    os.killpg(process.pid, signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130 and "--resume" in err and "Traceback" not in err, err
    wait_for(lambda: not session_processes(process.pid), 20, "the workers to end")
    assert evaluate(out, "--agent", "jerk", "--resume") == 0
    assert summary(out) == summary(reference)
