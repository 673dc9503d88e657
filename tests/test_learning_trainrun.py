"""``retrokit train``'s run folder without a library: its checkpoints, its resume, and damaged folders refused."""

from __future__ import annotations

import dataclasses
import json
import os

import pytest

from retrokit.benchmark.definition import load_benchmark
from retrokit.errors import FileConflictError, RunFolderError
from retrokit.learning.config import load_config
from retrokit.learning.policy import read_policy
from retrokit.learning.trainrun import Training, TrainRun

OBSERVATION = {"shape": [4, 84, 84], "dtype": "uint8", "options": {"frame_stack": 4}}


@pytest.fixture
def training() -> Training:
    benchmark = load_benchmark("dasher")
    return Training(benchmark, benchmark.train, "ppo", load_config("ppo", "quick"), 1000, seed=3)


@pytest.fixture
def saved(tmp_path, training):
    """A run that saved a checkpoint at 500 timesteps after 2 episodes, then one more episode, then was killed."""
    out = tmp_path / "run"
    run = TrainRun(out, training, resume=False, progress=False)
    run.episode("Dasher-Genesis/Zone1.Act1", 120.0, 80, 300)
    run.episode("Dasher-Genesis/Zone2.Act1", 90.0, 60, 400)
    run.save(500, b"weights-500", b"state-500", OBSERVATION, "test 1.0")
    run.episode("Dasher-Genesis/Zone1.Act1", 300.0, 90, 600)  # after the checkpoint: played again on resume
    run.close()
    return out


def test_a_checkpoint_resumes_with_its_weights_state_and_episodes(saved, training) -> None:
    run = TrainRun(saved, training, resume=True, progress=False)
    try:
        assert run.timesteps == 500 and run.resume_state() == (b"weights-500", b"state-500")
        assert [len(run.episodes[level.name]) for level in training.levels] == [1, 1, 0]
        assert (saved / "curve.csv").read_text().count("\n") == 3  # the header and the 2 episodes kept
    finally:
        run.close()
    policy = read_policy(saved, "ppo")
    assert policy.meta["timesteps"] == 500 and policy.read_weights() == b"weights-500"
    assert policy.meta["actions"][0] == ["LEFT"] and policy.meta["config"]["name"] == "quick"


def test_a_new_run_never_takes_a_used_folder_and_resume_needs_one(saved, tmp_path, training) -> None:
    with pytest.raises(FileConflictError, match="already holds a training run"):
        TrainRun(saved, training, resume=False, progress=False)
    with pytest.raises(RunFolderError, match="to hold a training run to resume"):
        TrainRun(tmp_path / "empty", training, resume=True, progress=False)
    other = Training(training.benchmark, training.levels, "ppo", training.config, 2000, seed=3)
    with pytest.raises(RunFolderError, match="timesteps differ"):
        TrainRun(saved, other, resume=True, progress=False)


def test_the_backend_is_a_setting_and_an_older_run_json_is_a_local_runs(saved, training) -> None:
    on_ray = dataclasses.replace(training, backend="ray", env_runners=3)
    with pytest.raises(RunFolderError, match="backend, env_runners differ"):
        TrainRun(saved, on_ray, resume=True, progress=False)
    _edit_run(saved, lambda data: [data["settings"].pop(key) for key in ("backend", "env_runners")])
    TrainRun(saved, training, resume=True, progress=False).close()
    with pytest.raises(RunFolderError, match="backend, env_runners differ"):
        TrainRun(saved, on_ray, resume=True, progress=False)


def test_a_folder_in_use_is_refused(saved, training) -> None:
    first = TrainRun(saved, training, resume=True, progress=False)
    try:
        with pytest.raises(RunFolderError, match="Expected no other training run running in the folder .*; found one there"):
            TrainRun(saved, training, resume=True, progress=False)
    finally:
        first.close()
    TrainRun(saved, training, resume=True, progress=False).close()  # free again once the first is closed


def _edit_run(saved, change) -> None:
    data = json.loads((saved / "run.json").read_text())
    change(data)
    (saved / "run.json").write_text(json.dumps(data))


def _checkpoint_file(saved, kind):
    return saved / "checkpoint" / json.loads((saved / "run.json").read_text())["checkpoint"][kind]["file"]


@pytest.mark.parametrize(("damage", "message"), [
    (lambda d: (d / "run.json").write_text("{"), "run.json to resume, but it is not JSON"),
    (lambda d: (d / "run.json").write_bytes(b" " * (2 << 20)), "of at most 1 MiB"),
    (lambda d: ((d / "run.json").unlink(), os.mkfifo(d / "run.json")), "a FIFO"),
    (lambda d: _edit_run(d, lambda r: r["checkpoint"].update(timesteps="x")), "its checkpoint has no timesteps"),
    (lambda d: _edit_run(d, lambda r: r["checkpoint"]["weights"].update(file="../x.pt")), "weights is not"),
    (lambda d: _edit_run(d, lambda r: r["checkpoint"]["episodes"].update(extra=1)), "episodes are not one count"),
    (lambda d: (d / "curve.csv").write_text("nonsense\n"), "curve.csv to resume, but its first line"),
    (lambda d: (d / "curve.csv").write_text("timesteps,level,episode,steps,reward,wall\n"), "fewer episodes"),
    (lambda d: ((d / "curve.csv").unlink(), (d / "curve.csv").symlink_to("/dev/zero")), "a device"),
], ids=["run-not-json", "run-huge", "run-fifo", "timesteps", "traversal", "levels", "curve-header", "curve-short",
        "curve-dev-zero"])
def test_a_damaged_folder_is_refused_in_one_line(saved, training, damage, message) -> None:
    damage(saved)
    with pytest.raises(RunFolderError, match=message) as caught:
        TrainRun(saved, training, resume=True, progress=False)
    assert "\n" not in str(caught.value)


def test_a_changed_checkpoint_file_is_refused(saved, training) -> None:
    _checkpoint_file(saved, "state").write_bytes(b"state-other")
    run = TrainRun(saved, training, resume=True, progress=False)
    try:
        with pytest.raises(RunFolderError, match="its digest is not the one run.json names"):
            run.resume_state()
    finally:
        run.close()
