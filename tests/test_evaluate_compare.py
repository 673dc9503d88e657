"""``retrokit evaluate --agent A --agent B``: each agent into OUT/<agent>/, and one side-by-side report and plot."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from evaluating import write_agents
from PIL import Image

from retrokit.benchmark.comparison import agent_folders
from retrokit.cli import main

AGENTS = '''
import numpy as np

def still(env, budget, seed):
    """Presses nothing."""
    env.reset()
    while True:
        _, _, terminated, truncated, _ = env.step(np.zeros(env.action_space.shape, dtype=np.int8))
        if terminated or truncated:
            env.reset()

def broken(env, budget, seed):
    raise RuntimeError("not written yet")
'''


@pytest.fixture
def mine(tmp_path) -> Path:
    """A user's benchmark file: two Dasher levels, 150 timesteps each."""
    path = tmp_path / "mine.yaml"
    path.write_text("name: mine\nbudget: 150\nenv: {frameskip: 4, max_episode_steps: 100}\n"
                    "levels:\n  test: [Dasher-Genesis/Zone1.Act1, Dasher-Genesis/Zone3.Act2]\n")
    return path


def run(mine: Path, out: Path, *agents: str, extra: tuple[str, ...] = ()) -> int:
    return main(["evaluate", "--benchmark", str(mine), "--no-progress", "--workers", "2", "--out", str(out),
                 *(a for agent in agents for a in ("--agent", agent)), *extra])


def test_several_agents_run_into_their_folders_and_one_report_compares_them(mine, tmp_path, capsys) -> None:
    agents = write_agents(tmp_path, AGENTS)
    out = tmp_path / "run"
    assert run(mine, out, "jerk", "random", f"{agents}:still") == 0
    printed = capsys.readouterr().out
    assert "jerk" in printed and "random" in printed and f"{agents}:still" in printed
    summaries = {name: json.loads((out / name / "summary.json").read_text()) for name in ("jerk", "random", "still")}
    assert all(s["benchmark"] == "mine" and s["complete"] for s in summaries.values())
    assert summaries["still"]["agent"] == f"{agents}:still"
    report = (out / "report.md").read_text()
    assert f"| level | jerk | random | {agents}:still |" in report
    for level in ("Dasher-Genesis/Zone1.Act1", "Dasher-Genesis/Zone3.Act2"):
        cells = [f"{s['levels'][level]['mean_score']:,.1f}" for s in summaries.values()]
        assert any(line.startswith(f"| {level} | {cells[0]}") and all(c in line for c in cells)
                   for line in report.splitlines()), report
    assert "**aggregate**" in report and "[jerk](jerk/report.md)" in report
    finals = report[report.index("## Final scores"):]
    assert f"| level | jerk | random | {agents}:still |" in finals and "paper" not in report.lower()
    for level in ("Dasher-Genesis/Zone1.Act1", "Dasher-Genesis/Zone3.Act2"):
        cells = " | ".join(f"{s['levels'][level]['final_score']:,.1f}" for s in summaries.values())
        assert f"| {level} | {cells} |" in finals
    assert " | ".join(f"**{s['final_aggregate']:,.1f}**" for s in summaries.values()) in finals
    for png, size in (("scores.png", None), ("mean-learning-curve.png", (640, 400))):
        with Image.open(out / png) as image:
            assert image.format == "PNG" and size in (None, image.size)
        assert f"({png})" in report
    assert all((out / name / "mean-learning-curve.png").is_file() for name in ("jerk", "random", "still"))
    before = (out / "report.md").read_bytes()
    assert run(mine, out, "jerk", "random", f"{agents}:still") == 2
    assert "already holds" in capsys.readouterr().err
    assert run(mine, out, "jerk", "random", f"{agents}:still", extra=("--resume",)) == 0
    assert (out / "report.md").read_bytes() == before
    shutil.rmtree(out / "still")  # as if interrupted before the last agent's turn
    assert run(mine, out, "jerk", "random", f"{agents}:still", extra=("--resume",)) == 0
    assert (out / "report.md").read_bytes() == before


def test_an_agent_that_fails_does_not_stop_the_others(mine, tmp_path, capsys) -> None:
    agents = write_agents(tmp_path, AGENTS)
    out = tmp_path / "run"
    assert run(mine, out, f"{agents}:broken", "random") == 2
    err = capsys.readouterr().err
    assert f"Agent '{agents}:broken'" in err and "raised RuntimeError: not written yet" in err and err.count("\n") == 1
    assert json.loads((out / "random" / "summary.json").read_text())["complete"]
    report = (out / "report.md").read_text()
    assert "| Dasher-Genesis/Zone1.Act1 | failed |" in report and "Not complete: " in report


def test_agent_folders_are_file_names_and_unique() -> None:
    assert agent_folders(["jerk", "random", "my_agents.py:ppo", "other/agents.py:ppo", "pkg.mod:../x"]) == {
        "jerk": "jerk", "random": "random", "my_agents.py:ppo": "ppo", "other/agents.py:ppo": "ppo-2",
        "pkg.mod:../x": "x"}
