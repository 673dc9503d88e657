"""The report and plots beside the paper's scores (which ship with retrokit), exercised with the paper's own numbers."""

from __future__ import annotations

import contextlib
import io
import json
import os
import tomllib
from pathlib import Path

import pytest
from PIL import Image

from retrokit.benchmark import plots
from retrokit.benchmark.comparison import render_comparison
from retrokit.benchmark.definition import load_benchmark
from retrokit.benchmark.monitor import Episode
from retrokit.benchmark.paper import (
    PAPER_ENV,
    PAPER_LEVELS,
    SHIPPED_DIR,
    find_paper_dir,
    has_paper_scores,
    load_paper,
    paper_name,
)
from retrokit.benchmark.report import render_report
from retrokit.benchmark.rundir import FinishedLevel
from retrokit.benchmark.scores import (
    FROM_UNFINISHED,
    UNFINISHED_NOTE,
    Episodes,
    LevelScore,
    Summary,
    aggregate,
    mean_curve,
    summarize,
)
from retrokit.cli import main

REPO = Path(__file__).resolve().parent.parent
paper = load_paper()
BUDGET = 1_000_000


def as_summary(agent: str, scores: dict[str, float]) -> Summary:
    levels = {level: LevelScore(s, 1, BUDGET, 0.0, s) for level, s in scores.items()}
    return Summary("sonic", agent, 0, BUDGET, True, levels, aggregate(levels), paper_agent=paper_name(agent))


def from_episodes(agent: str, wanted: dict[str, tuple[float, float]], init: str | None = None) -> Summary:
    """The summary of a run on the paper's levels whose episodes give each level the (score, final score) wanted.

    Two episodes a level: one early, and one in the budget's last 10%, which alone makes the final score.
    """
    episodes = {level: [Episode(1, 4500, 2 * score - final, 4500, 1.0), Episode(2, 4500, final, 950_000, 2.0)]
                for level, (score, final) in wanted.items()}
    settings = {"benchmark": {"name": "sonic"}, "agent": agent, "seed": 0, "budget": BUDGET, "levels": list(wanted),
                # a learning agent's run names its paper row in its setup, "Joint ..." when it starts from a policy
                **({"agent_setup": {"paper_agent": paper_name(agent, init)}} if init is not None else {})}
    return summarize(settings, {level: FinishedLevel(BUDGET, 2) for level in wanted}, episodes)


def papers_plus(agent: str, more: float, more_final: float) -> dict[str, tuple[float, float]]:
    """The paper's per-level (score, final score) of ``agent``, raised by ``more`` and ``more_final``."""
    return {level: (e.score + more, e.final + more_final) for level, e in paper.levels[agent].items()}


def shared_copy() -> Path | None:
    """The project's own copy of the paper's scores (shared/paper beside the checkout or a folder above), if here."""
    return next((folder / "shared" / "paper" / "test-scores.csv" for folder in REPO.parents
                 if (folder / "shared" / "paper" / "test-scores.csv").is_file()), None)


def test_the_papers_scores_ship_with_retrokit(monkeypatch) -> None:
    monkeypatch.delenv(PAPER_ENV, raising=False)
    assert find_paper_dir() == SHIPPED_DIR and paper is not None and paper.shipped
    assert paper.path == SHIPPED_DIR / "test-scores.csv" and "from retrokit's copy" in paper.source
    assert list(paper.aggregates) == ["Rainbow", "JERK", "PPO", "Joint PPO", "Joint Rainbow", "Human"]
    assert paper.aggregates["Joint PPO"] == (3127.9, 116.9, 3926.3, 78.1)  # Table 1's best learner
    assert paper.aggregates["Human"].final is None and paper.table("JERK") == 3 and paper.table("Joint Rainbow") == 6
    patterns = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["retrokit"]
    shipped = {p for pattern in patterns for p in (REPO / "retrokit").glob(pattern)}
    assert {SHIPPED_DIR / "test-scores.csv", SHIPPED_DIR / "README.md"} <= shipped


@pytest.mark.skipif(shared_copy() is None, reason="the project's shared/paper folder is not beside this checkout")
def test_the_shipped_scores_equal_the_projects_copy() -> None:
    assert (SHIPPED_DIR / "test-scores.csv").read_bytes() == shared_copy().read_bytes()


def test_retrokit_paper_names_another_copy(tmp_path, monkeypatch) -> None:
    text = (SHIPPED_DIR / "test-scores.csv").read_text().replace("JERK,,Aggregate,1904.0", "JERK,,Aggregate,1999.0")
    (tmp_path / "test-scores.csv").write_text(text)
    monkeypatch.setenv(PAPER_ENV, str(tmp_path))
    other = load_paper()
    assert other.aggregates["JERK"].score == 1999.0 and not other.shipped and str(tmp_path) in other.source


def test_the_papers_test_levels_are_the_sonic_benchmarks() -> None:
    test = {level.name for level in load_benchmark("sonic").test}
    assert test == PAPER_LEVELS
    for agent in ("Rainbow", "JERK", "PPO", "Joint PPO", "Joint Rainbow", "Human"):
        assert set(paper.levels[agent]) == test, agent


@pytest.mark.parametrize("agent", ["Rainbow", "JERK", "PPO", "Joint PPO", "Joint Rainbow", "Human"])
def test_our_aggregate_of_the_papers_level_scores_is_its_aggregate(agent) -> None:
    scores = {level: entry.score for level, entry in paper.levels[agent].items()}
    assert as_summary(agent, scores).aggregate == pytest.approx(paper.aggregates[agent].score, abs=0.06)
    if agent != "Human":  # the paper's final aggregate is the mean of its final scores too
        finals = [entry.final for entry in paper.levels[agent].values()]
        assert sum(finals) / len(finals) == pytest.approx(paper.aggregates[agent].final, abs=0.06)


def test_the_report_puts_each_level_beside_the_papers_table_3_for_jerk() -> None:
    summary = from_episodes("jerk", papers_plus("JERK", 100.0, 50.0))
    assert summary.paper_agent == "JERK"
    text = render_report(summary, paper, plots=[])
    assert "## Per level, beside the paper's Table 3 (JERK)" in text
    assert "| paper (JERK) | paper final score | ours − paper |" in text
    for level, entry in paper.levels["JERK"].items():
        mine = summary.levels[level]
        assert mine.final_score == pytest.approx(entry.final + 50.0) and mine.final_episodes == 1
        assert f"| {level} | {entry.score + 100:,.1f} | " in text
        assert f"| {entry.final + 50:,.1f} | 2 | 1,000,000 |" in text
        assert f"| {entry.score:,.1f} | {entry.final:,.1f} | 100.0 |" in text
    table_one = text[text.index("## Beside the paper's Table 1"):].splitlines()
    jerk = next(i for i, line in enumerate(table_one) if line.startswith("| JERK (paper) |"))
    assert table_one[jerk] == "| JERK (paper) | 1,904.0 | 21.9 | 2,306.8 | 74.0 |"
    ours = table_one[jerk + 1]
    assert ours.startswith("| **jerk** (this run) | **") and ours.endswith(" | – |")
    assert f"**{summary.aggregate:,.1f}**" in ours and f"**{summary.final_aggregate:,.1f}**" in ours
    assert summary.aggregate == pytest.approx(paper.aggregates["JERK"].score + 100, abs=0.06)
    assert sum(1 for line in table_one if "(paper)" in line) == 6  # every row of the paper's Table 1


@pytest.mark.parametrize(("agent", "init", "name", "table"), [
    ("ppo", None, "PPO", 4), ("ppo", "runs/joint", "Joint PPO", 5),
    ("rainbow", None, "Rainbow", 2), ("rainbow", "runs/joint/policy.zip", "Joint Rainbow", 6)])
def test_the_learning_agents_meet_their_rows_joint_with_init(agent, init, name, table) -> None:
    summary = from_episodes(agent, papers_plus(name, -10.0, 0.0), init=init)
    text = render_report(summary, paper, plots=[])
    assert summary.paper_agent == name and f"beside the paper's Table {table} ({name})" in text
    lines = text.splitlines()
    row = lines.index(next(line for line in lines if line.startswith(f"| {name} (paper) |")))
    assert lines[row + 1].startswith(f"| **{agent}** (this run) |")
    first = next(iter(paper.levels[name].items()))
    assert f"| {first[1].score:,.1f} | {first[1].final:,.1f} | -10.0 |" in text


@pytest.mark.parametrize(("ours", "init", "theirs"), [
    ("jerk", None, "JERK"), ("my_agents.py:ppo", None, "PPO"), ("pkg.mod:Rainbow", None, "Rainbow"),
    ("PPO", "", "PPO"), ("jerk", "x", "JERK"), ("pkg.mod:rainbow", "x", "Joint Rainbow"),
    ("random", None, None), ("random", "x", None), ("pkg.mod:random", None, None)])
def test_our_agents_are_matched_to_the_papers_by_name(ours, init, theirs) -> None:
    assert paper_name(ours, init) == theirs == paper.agent(ours, init)


def test_an_agent_the_paper_did_not_run_comes_last_in_table_1() -> None:
    text = render_report(as_summary("random", {"SonicTheHedgehog-Genesis/GreenHillZone.Act2": 500.0}), paper, plots=[])
    assert "paper (" not in text and "did not run 'random'" in text and "| Rainbow (paper) | 2,748.6 |" in text
    last = [line for line in text[text.index("## Beside the paper's Table 1"):].splitlines() if "|" in line][-1]
    assert last == "| **random** (this run, 1 of the 11 levels) | **500.0** | – | **500.0** | – |"


def test_several_agents_side_by_side_each_beside_its_papers_column() -> None:
    summaries = {"jerk": from_episodes("jerk", papers_plus("JERK", 1.0, 2.0)),
                 "ppo": from_episodes("ppo", papers_plus("Joint PPO", 3.0, 4.0), init="joint"),
                 "random": from_episodes("random", papers_plus("PPO", -5.0, -6.0))}
    levels = [level.name for level in load_benchmark("sonic").test]
    text = render_comparison(summaries, {a: a for a in summaries}, levels, "three", {}, paper, paper_levels=True)
    scores, finals = text.split("## Final scores")
    header = "| level | jerk | JERK (paper) | ppo | Joint PPO (paper) | random |"
    assert header in scores and header in finals
    for level in levels:
        jerk, joint, ppo = paper.levels["JERK"][level], paper.levels["Joint PPO"][level], paper.levels["PPO"][level]
        assert (f"| {level} | {jerk.score + 1:,.1f} | {jerk.score:,.1f} | {joint.score + 3:,.1f} | "
                f"{joint.score:,.1f} | {ppo.score - 5:,.1f} |") in scores
        assert (f"| {level} | {jerk.final + 2:,.1f} | {jerk.final:,.1f} | {joint.final + 4:,.1f} | "
                f"{joint.final:,.1f} | {ppo.final - 6:,.1f} |") in finals
    table_one = finals[finals.index("## Beside the paper's Table 1"):].splitlines()
    rows = [line.split(" |")[0] for line in table_one if line.startswith("| ") and "---" not in line][1:]
    assert rows == ["| Rainbow (paper)", "| JERK (paper)", "| **jerk** (this run)", "| PPO (paper)",
                    "| Joint PPO (paper)", "| **ppo** (this run)", "| Joint Rainbow (paper)", "| Human (paper)",
                    "| **random** (this run)"]


def test_the_instantaneous_score_is_the_mean_of_the_window_else_the_last_episode() -> None:
    ended = Episodes([Episode(n, 10, reward, end, 0.0) for n, (reward, end) in
                      enumerate([(1.0, 10), (2.0, 20), (30.0, 95), (40.0, 99), (50.0, 100)], start=1)])
    assert ended.instantaneous(100, 10) == (40.0, 3)  # the episodes that ended in (90, 100]
    assert ended.instantaneous(50, 10) == (2.0, 1)  # none in (40, 50]: the last that ended by 50
    assert ended.instantaneous(20, 15) == (1.5, 2) and ended.instantaneous(9, 10) is None
    curve = mean_curve({"a": [Episode(1, 5, 10.0, 5, 0.0)], "b": [Episode(1, 50, 30.0, 50, 0.0)], "c": []}, 100, 10)
    assert curve == {"timesteps": [10, 20, 30, 40, 50, 60, 70, 80, 90, 100],
                     "score": [None, None, None, None, 20.0, 20.0, 20.0, 20.0, 20.0, 20.0]}


def test_the_scores_plot_draws_ours_beside_the_papers() -> None:
    levels = sorted(paper.levels["JERK"])
    series = {"jerk": {lv: e.score for lv, e in paper.levels["Rainbow"].items()},
              "paper (JERK)": {lv: e.score for lv, e in paper.levels["JERK"].items()}}
    with Image.open(io.BytesIO(plots.score_bars(series, levels, "test"))) as image:
        assert image.format == "PNG" and image.size[1] > 400  # 11 levels of two bars each


def test_without_the_paper_the_report_says_so(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv(PAPER_ENV, str(tmp_path))  # a folder without test-scores.csv
    assert find_paper_dir() is None and load_paper() is None
    text = render_report(as_summary("jerk", {"SonicTheHedgehog-Genesis/GreenHillZone.Act2": 5.0}), None, plots=[])
    assert "The paper's scores were not found" in text and "| SonicTheHedgehog-Genesis/GreenHillZone.Act2 | 5.0 |" in text
    assert "Table 1" not in text


def test_a_benchmark_the_paper_did_not_score_says_nothing_of_the_paper() -> None:
    levels = ["Dasher-Genesis/Zone1.Act2"]
    assert not has_paper_scores(levels) and has_paper_scores(["SonicTheHedgehog-Genesis/GreenHillZone.Act2"])
    text = render_report(as_summary("jerk", dict.fromkeys(levels, 5.0)), paper, plots=[],
                         paper_levels=has_paper_scores(levels))
    assert "paper" not in text.lower() and "Table" not in text and "| Dasher-Genesis/Zone1.Act2 | 5.0 |" in text


@pytest.mark.parametrize("content", [
    b"agent,game\n\xff\xfe\x00garbage",  # not UTF-8
    b"agent,game,state,score\nJERK,,Aggregate,12\n",  # columns missing
    b"agent,game,state,score,score_sd,final_score,final_score_sd\nJERK,,Aggregate,nan,1,2,3\n",  # not finite
    b"agent,game,state,score,score_sd,final_score,final_score_sd\n" + b"JERK,,Aggregate,1,1,1,1\n" * 60_000,  # 1.4 MB
], ids=["not-utf8", "columns-missing", "nan", "huge"])
def test_a_damaged_paper_file_is_treated_as_absent(tmp_path, monkeypatch, content) -> None:
    (tmp_path / "test-scores.csv").write_bytes(content)
    monkeypatch.setenv(PAPER_ENV, str(tmp_path))
    assert load_paper() is None


def test_a_fifo_in_the_papers_place_is_no_paper(tmp_path, monkeypatch) -> None:
    os.mkfifo(tmp_path / "test-scores.csv")  # reading it would block forever
    monkeypatch.setenv(PAPER_ENV, str(tmp_path))
    assert find_paper_dir() is None and load_paper(tmp_path) is None


@pytest.fixture(scope="module")
def short_jerk(tmp_path_factory) -> tuple[Path, str, str]:
    """JERK on two levels for 60 timesteps, showing its progress, without the paper: the run, its stdout, stderr.

    60 timesteps: JERK finishes no episode on Zone2.Act2 (its episodes last hundreds of steps), two on Zone3.Act2.
    Its output goes to strings, which are no terminal (as pytest's captured stdout and stderr are not).
    """
    folder = tmp_path_factory.mktemp("short-jerk")
    out, stdout, stderr = folder / "run", io.StringIO(), io.StringIO()
    with pytest.MonkeyPatch.context() as patch, contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        patch.setenv(PAPER_ENV, str(folder))  # no paper: a Dasher report must not mention it anyway
        code = main(["evaluate", "--levels", "Zone2.Act2,Zone3.Act2", "--timesteps", "60", "--agent", "jerk",
                     "--out", str(out)])
    assert code == 0, stderr.getvalue()
    return out, stdout.getvalue(), stderr.getvalue()


def test_a_level_that_finished_no_episode_scores_its_unfinished_episode(short_jerk) -> None:
    out = short_jerk[0]
    data = json.loads((out / "summary.json").read_text())
    empty, played = data["levels"]["Dasher-Genesis/Zone2.Act2"], data["levels"]["Dasher-Genesis/Zone3.Act2"]
    assert empty["episodes"] == 0 and empty["scored_from"] == FROM_UNFINISHED and empty["mean_score"] > 0
    assert empty["final_score"] == empty["mean_score"] and empty["final_episodes"] == 0
    assert data["curve"]["score"][-1] == played["final_score"]  # a level without an episode is not in the curve
    assert played["episodes"] > 0 and played["scored_from"] == "finished episodes"
    assert data["aggregate"] == pytest.approx((empty["mean_score"] + played["mean_score"]) / 2)
    assert data["notes"] == [UNFINISHED_NOTE]
    report = (out / "report.md").read_text()
    assert UNFINISHED_NOTE in report and "| Dasher-Genesis/Zone2.Act2 * |" in report
    assert "paper" not in report.lower()


def test_without_a_terminal_each_level_prints_one_line(short_jerk) -> None:
    _, out, err = short_jerk
    lines = [line for line in out.splitlines() if line.startswith("[")]
    assert sorted(line[:5] for line in lines) == ["[1/2]", "[2/2]"], out
    assert all(": done, " in line and "score" in line for line in lines)
    assert "\r" not in out + err and "\x1b" not in out + err
