"""Hostile agents and damaged run folders: each ends in a one-line error or a correct, honest result.

The agents are written by the tests: they end their process, crash natively,
stall, swallow ``BudgetSpent``, return early or play ``env.unwrapped``, each on
its own Dasher level, so one run shows that the others are kept. The damaged
folders are a finished run's, broken by hand.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from childproc import MAX_RSS_MB, Child, run_cli, run_cli_cases_in_child
from evaluating import session_processes, wait_for, write_agents

from retrokit.cli import main

AGENTS = '''
import ctypes, os, pathlib, time
import numpy as np

def _normal(env):
    env.reset()
    while True:
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()

def _fixed():
    flag = os.environ.get("RETROKIT_TEST_FLAG")
    return flag is not None and pathlib.Path(flag).exists()

def ends_its_process(env, budget, seed):
    """Ends its process in four ways, one a level; plays Zone2.Act1 normally, leaving a thread that never ends."""
    state = env.unwrapped.state_name
    env.reset()
    for _ in range(20):
        env.step(env.action_space.sample())
    if state == "Zone1.Act2":
        os._exit(0)
    if state == "Zone2.Act2":
        raise SystemExit(0)
    if state == "Zone3.Act2":
        os._exit(3)
    if state == "Zone1.Act1":
        ctypes.string_at(0)  # a native crash: SIGSEGV
    import threading
    threading.Thread(target=time.sleep, args=(10**6,)).start()  # a thread that would keep its process alive
    _normal(env)

def stalls(env, budget, seed):
    """Sleeps, spins, swallows BudgetSpent, steps env.unwrapped forever; plays normally once the flag exists."""
    state = env.unwrapped.state_name
    if _fixed() or state == "Zone2.Act1":
        _normal(env)
    env.reset()
    for _ in range(10):
        env.step(env.action_space.sample())
    if state == "Zone1.Act2":
        time.sleep(10**6)
    if state == "Zone2.Act2":
        while True:
            pass
    if state == "Zone3.Act2":
        while True:
            try:
                _, _, terminated, truncated, _ = env.step(env.action_space.sample())
                if terminated or truncated:
                    env.reset()
            except BaseException:
                pass
    raw = env.unwrapped
    while True:
        _, _, terminated, truncated, _ = raw.step(raw.action_space.sample())
        if terminated or truncated:
            raw.reset()

def returns_early(env, budget, seed):
    """Returns after 10 steps, at once, or after playing env.unwrapped; plays normally once the flag exists."""
    state = env.unwrapped.state_name
    if _fixed():
        _normal(env)
    if state == "Zone1.Act2":
        env.reset()
        for _ in range(10):
            env.step(env.action_space.sample())
        return
    if state == "Zone2.Act2":
        return
    raw = env.unwrapped
    raw.reset()
    for _ in range(300):
        raw.step(raw.action_space.sample())
'''

THREE = "Zone1.Act2,Zone2.Act2,Zone3.Act2"
FAST = ["evaluate", "--benchmark", "dasher", "--timesteps", "200", "--no-progress"]


@pytest.fixture
def agents(tmp_path) -> Path:
    return write_agents(tmp_path, AGENTS)


def report(out: Path) -> str:
    return (out / "report.md").read_text()


@pytest.fixture(scope="module")
def ended(tmp_path_factory) -> tuple[dict[str, Child], Child, Path]:
    """The agent that ends its process on five levels, on one worker and on two, in one child: what each run said,
    the child, and the folder of the runs (``1``, ``2``)."""
    root = tmp_path_factory.mktemp("ended")
    agents = write_agents(root, AGENTS)
    commands = {workers: [*FAST, "--levels", f"{THREE},Zone1.Act1,Zone2.Act1", "--agent", f"{agents}:ends_its_process",
                          "--workers", workers, "--out", str(root / workers)] for workers in ("1", "2")}
    outcomes, child = run_cli_cases_in_child(commands, timeout=240)
    assert child.returncode == 0 and child.stderr == "", child.describe()  # no worker printed anything of its own
    return outcomes, child, root


@pytest.mark.parametrize("workers", ["1", "2"])
def test_an_agent_that_ends_its_process_fails_its_level_and_the_others_are_kept(ended, workers) -> None:
    outcomes, child, root = ended
    code, stderr = outcomes[workers].returncode, outcomes[workers].stderr
    out = root / workers
    assert code == 2, (code, stderr, child.describe())
    assert stderr.count("\n") == 1 and "Traceback" not in stderr, stderr
    assert "4 more level(s) failed" not in stderr and "3 more level(s) failed" in stderr, stderr
    data = json.loads((out / "summary.json").read_text())
    assert list(data["levels"]) == ["Dasher-Genesis/Zone2.Act1"] and data["complete"] is False
    text = report(out)
    for level, how in [("Zone1.Act2", "exited with status 0 (its last report: step"),
                       ("Zone2.Act2", "raised SystemExit: 0 (level Dasher-Genesis/Zone2.Act2, step 21"),
                       ("Zone3.Act2", "exited with status 3 (its last report: step"),
                       ("Zone1.Act1", "was killed by signal SIGSEGV (its last report: step")]:
        assert f"- Dasher-Genesis/{level}: " in text and how in text, (level, text)


def test_a_stalled_level_is_stopped_and_the_run_resumes_to_the_uninterrupted_result(agents, tmp_path,
                                                                                   monkeypatch) -> None:
    # All five levels play at once, so the four stalls run out their timeout together (the spinning ones burn a
    # core each while they wait). The timeout only has to outlast a gap between the normal level's reports,
    # which come twice a second; the resumed and fresh runs, where nothing stalls, keep the default.
    out, flag = tmp_path / "run", tmp_path / "fixed"
    args = [*FAST, "--levels", f"{THREE},Zone1.Act1,Zone2.Act1", "--agent", f"{agents}:stalls", "--workers", "5"]
    env = {"RETROKIT_TEST_FLAG": str(flag)}
    began = time.monotonic()
    child = run_cli([*args, "--stall-timeout", "2", "--out", str(out)], timeout=240, env=env)
    assert child.returncode == 2 and "stalled and was stopped after 2 s" in child.stderr, child.describe()
    assert time.monotonic() - began < 200
    text = report(out)
    assert "Zone1.Act2: Level Dasher-Genesis/Zone1.Act2 stalled" in text and "no timestep after step 10 of 200" in text
    assert "Zone3.Act2: Level Dasher-Genesis/Zone3.Act2 stalled" in text and "swallows it" in text
    assert text.count("steps env.unwrapped, which the budget does not count") == 3  # Zone1.Act2, Zone2.Act2, Zone1.Act1
    assert list(json.loads((out / "summary.json").read_text())["levels"]) == ["Dasher-Genesis/Zone2.Act1"]
    flag.touch()
    # Once the flag exists nothing stalls: the resumed and the fresh run play in this process (their workers are
    # still processes, which inherit the flag's variable), sparing two interpreters' start.
    monkeypatch.setenv("RETROKIT_TEST_FLAG", str(flag))
    assert main([*args, "--out", str(out), "--resume"]) == 0
    assert main([*args, "--out", str(tmp_path / "fresh")]) == 0
    assert (out / "summary.json").read_bytes() == (tmp_path / "fresh" / "summary.json").read_bytes()


def test_an_agent_that_returns_early_is_not_complete_and_is_replayed(agents, tmp_path, monkeypatch, capsys) -> None:
    flag = tmp_path / "fixed"
    monkeypatch.setenv("RETROKIT_TEST_FLAG", str(flag))
    out = tmp_path / "run"
    args = [*FAST, "--levels", THREE, "--agent", f"{agents}:returns_early", "--workers", "2", "--out", str(out)]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "until its budget of 200 timesteps was spent, but it returned after" in err and err.count("\n") == 1
    data = json.loads((out / "summary.json").read_text())
    assert data["complete"] is False and data["levels"] == {}
    text = report(out)
    assert "0 level(s) finished (the run is not complete)" in text and "returned after 10;" in text
    assert text.count("returned after 0;") == 2  # at once, and after playing env.unwrapped
    flag.touch()
    assert main([*args, "--resume"]) == 0
    data = json.loads((out / "summary.json").read_text())
    assert data["complete"] is True and all(e["timesteps"] == 200 for e in data["levels"].values())


def test_a_killed_evaluation_leaves_no_worker_playing(tmp_path) -> None:
    command = [sys.executable, "-m", "retrokit", *FAST, "--levels", THREE, "--timesteps", "1000000",
               "--agent", "random", "--workers", "2", "--out", str(tmp_path / "run")]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        wait_for(lambda: (tmp_path / "run" / "episodes.jsonl").is_file() and len(session_processes(process.pid)) >= 3,
                 120, "the evaluation and its two workers")
        os.kill(process.pid, signal.SIGKILL)
        process.wait(timeout=30)
        wait_for(lambda: not session_processes(process.pid), 20, "the workers to end with their parent")
    finally:
        for pid in session_processes(process.pid):
            os.kill(pid, signal.SIGKILL)


def test_an_unreachable_ray_address_times_out_with_a_clear_message(tmp_path, capsys) -> None:
    began = time.monotonic()
    assert main([*FAST, "--levels", "Zone1.Act2", "--backend", "ray", "--ray-address", "127.0.0.1:9",
                 "--out", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err
    assert "Expected a Ray cluster at 127.0.0.1:9, but it could not be reached" in err and err.count("\n") == 1
    assert time.monotonic() - began < 60


# Damaged run folders: a finished run of one level, broken by hand, then resumed.

LEVEL = "Dasher-Genesis/Zone3.Act2"


@pytest.fixture(scope="module")
def finished(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("finished") / "run"
    assert main([*FAST, "--levels", LEVEL, "--agent", "jerk", "--out", str(out)]) == 0
    return out


def _lines(out: Path) -> list[dict]:
    return [json.loads(line) for line in (out / "episodes.jsonl").read_text().splitlines()]


def _write_lines(out: Path, records: list) -> None:
    (out / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records))


def _edit_episode(**change):
    def damage(out: Path) -> None:
        records = _lines(out)
        records[0].update(change)
        for key, value in change.items():
            if value is _DROP:
                del records[0][key]
        _write_lines(out, records)
    return damage


def _edit_run(change):
    def damage(out: Path) -> None:
        data = json.loads((out / "run.json").read_text())
        change(data)
        (out / "run.json").write_text(json.dumps(data))
    return damage


def _replace(name: str, make):
    def damage(out: Path) -> None:
        (out / name).unlink()
        make(out / name)
    return damage


_DROP = object()


def _invalid_utf8(out: Path) -> None:
    text = (out / "episodes.jsonl").read_bytes()
    (out / "episodes.jsonl").write_bytes(b'{"level": "\xff\xfe"}\n' + text)


def _nested(out: Path) -> None:
    (out / "run.json").write_text('{"settings": {}, "finished": ' + "[" * 100_000 + "]" * 100_000 + "}")


def _raw_reward(text: str):
    def damage(out: Path) -> None:
        lines = (out / "episodes.jsonl").read_text().splitlines()
        record = json.loads(lines[0])
        lines[0] = json.dumps(record).replace(f'"reward": {json.dumps(record["reward"])}', f'"reward": {text}')
        (out / "episodes.jsonl").write_text("\n".join(lines) + "\n")
    return damage


DAMAGES = {
    "invalid-utf8-line": (_invalid_utf8, "episodes.jsonl to resume, but its line 1 is not JSON"),
    "level-a-list": (_edit_episode(level=[1, 2]), "its line 1 names no level"),
    "level-a-dict": (_edit_episode(level={"a": 1}), "its line 1 names no level"),
    "reward-text": (_edit_episode(reward="abc"), "'reward' must be a finite number, got 'abc'"),
    "no-episode-number": (_edit_episode(episode=_DROP), "'episode' must be a whole number"),
    "reward-nan": (_raw_reward("NaN"), "'reward' must be a finite number, got nan"),
    "reward-1e999": (_raw_reward("1e999"), "'reward' must be a finite number, got inf"),
    "finished-a-list": (_edit_run(lambda d: d.update(finished=[LEVEL])), "does not map 'settings' and 'finished'"),
    "finished-entry-an-int": (_edit_run(lambda d: d["finished"].update({LEVEL: 7})), "must be a mapping, got int"),
    "finished-timesteps-negative": (_edit_run(lambda d: d["finished"][LEVEL].update(timesteps=-5)),
                                    "must be whole numbers of 0 or more, got [-5"),
    "nested-100000-deep": (_nested, "run.json to resume, but it is not JSON (RecursionError)"),
    "episodes-a-fifo": (_replace("episodes.jsonl", os.mkfifo), "is not a regular file"),
    "run-json-a-fifo": (_replace("run.json", os.mkfifo), "is not a regular file"),
    "episodes-dev-zero": (_replace("episodes.jsonl", lambda p: p.symlink_to("/dev/zero")), "is not a regular file"),
    "run-json-dev-zero": (_replace("run.json", lambda p: p.symlink_to("/dev/zero")), "is not a regular file"),
    "huge-line": (lambda out: (out / "episodes.jsonl").write_bytes(b"1" * (1 << 20) + b"\n"), "longer than 65536"),
}


@pytest.fixture(scope="module")
def resumed_damages(finished, tmp_path_factory) -> tuple[dict[str, Child], Child]:
    """Each damaged copy of the finished run, resumed in turn in one child: what each said, and the child.

    One interpreter for all of them spares its start per damage; its peak memory is the largest any of them
    needed (and more), so it holds each to the limit.
    """
    folders = {}
    for damage, (make, _) in DAMAGES.items():
        folders[damage] = str(tmp_path_factory.mktemp(damage) / "run")
        shutil.copytree(finished, folders[damage])
        make(Path(folders[damage]))
    commands = {damage: [*FAST, "--levels", LEVEL, "--agent", "jerk", "--out", out, "--resume"]
                for damage, out in folders.items()}
    outcomes, child = run_cli_cases_in_child(commands, timeout=120)
    assert child.returncode == 0, child.describe()
    return outcomes, child


@pytest.mark.parametrize("damage", list(DAMAGES))
def test_a_damaged_run_folder_is_refused_in_one_line(resumed_damages, damage) -> None:
    outcomes, child = resumed_damages
    code, stderr = outcomes[damage].returncode, outcomes[damage].stderr
    expected = DAMAGES[damage][1]
    assert code == 2 and expected in stderr, (code, stderr)
    assert stderr.count("\n") == 1 and "Traceback" not in stderr, stderr
    assert child.peak_rss_mb < MAX_RSS_MB, child.describe()


def test_a_level_an_older_run_finished_early_is_played_again(finished, tmp_path) -> None:
    out = tmp_path / "run"
    shutil.copytree(finished, out)
    _edit_run(lambda d: d["finished"][LEVEL].update(timesteps=10))(out)
    assert main([*FAST, "--levels", LEVEL, "--agent", "jerk", "--out", str(out), "--resume"]) == 0
    assert (out / "summary.json").read_bytes() == (finished / "summary.json").read_bytes()


AT_IMPORT = {
    "sys-exit-0": "import sys\nsys.exit(0)\n",
    "os-exit-0": "import os\nos._exit(0)\n",
    "sys-exit-3": "import sys\nsys.exit(3)\n",
    "keyboard-interrupt": "raise KeyboardInterrupt\n",
}


@pytest.fixture(scope="module")
def at_import(tmp_path_factory) -> tuple[dict[str, Child], Child, Path]:
    """Each case's agent module evaluated in turn in ONE child: what each command said, the child, and the folder.

    A module that ended the evaluation's own process would end the child before it answered the later cases;
    anything a process under it wrote to the terminal is in the child's own stderr, which the test holds empty.
    """
    root = tmp_path_factory.mktemp("at-import")
    commands = {}
    for case, source in AT_IMPORT.items():
        (root / case).mkdir()
        agent = root / case / "quits.py"
        agent.write_text(source + "def agent(env, budget, seed):\n    pass\n")
        commands[case] = [*FAST, "--levels", "Zone1.Act1", "--agent", f"{agent}:agent", "--out", str(root / case / "run")]
    outcomes, child = run_cli_cases_in_child(commands, timeout=240, cwd=root)
    assert child.returncode == 0 and child.stderr == "", child.describe()
    return outcomes, child, root


@pytest.mark.parametrize("case", AT_IMPORT, ids=list(AT_IMPORT))
def test_an_agent_module_that_exits_at_import_is_one_line_and_a_failure(at_import, case) -> None:
    outcomes, child, root = at_import
    code, stderr = outcomes[case].returncode, outcomes[case].stderr
    assert code == 2, (code, stderr, child.describe())
    assert stderr.count("\n") == 1 and "Traceback" not in stderr, stderr
    assert "quits.py:agent" in stderr and not (root / case / "run").exists(), stderr
