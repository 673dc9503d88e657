"""The report and plots beside the paper's scores, exercised with the paper's own numbers."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import pytest
from PIL import Image

from retrokit.benchmark import plots
from retrokit.benchmark.definition import load_benchmark
from retrokit.benchmark.paper import PAPER_ENV, find_paper_dir, has_paper_scores, load_paper
from retrokit.benchmark.report import render_report
from retrokit.benchmark.scores import FROM_UNFINISHED, UNFINISHED_NOTE, LevelScore, Summary, aggregate
from retrokit.cli import main

paper = load_paper()
needs_paper = pytest.mark.skipif(paper is None, reason="the paper's test-scores.csv is not beside the repository")


def as_summary(agent: str, scores: dict[str, float]) -> Summary:
    levels = {level: LevelScore(s, 1, 1_000_000, 0.0, s) for level, s in scores.items()}
    return Summary("sonic", agent, 0, 1_000_000, True, levels, aggregate(levels))


@needs_paper
def test_the_papers_test_levels_are_the_sonic_benchmarks() -> None:
    test = {level.name for level in load_benchmark("sonic").test}
    for agent in ("Rainbow", "JERK", "PPO", "Joint PPO", "Joint Rainbow", "Human"):
        assert set(paper.levels[agent]) == test, agent


@needs_paper
@pytest.mark.parametrize("agent", ["Rainbow", "JERK", "PPO", "Joint PPO", "Joint Rainbow", "Human"])
def test_our_aggregate_of_the_papers_level_scores_is_its_aggregate(agent) -> None:
    scores = {level: score for level, (score, _) in paper.levels[agent].items()}
    assert as_summary(agent, scores).aggregate == pytest.approx(paper.aggregates[agent][0], abs=0.06)


@needs_paper
def test_the_report_puts_each_level_beside_the_papers_jerk() -> None:
    theirs = {level: score for level, (score, _) in paper.levels["JERK"].items()}
    ours = {level: score + 100.0 for level, score in theirs.items()}
    text = render_report(as_summary("jerk", ours), paper, plots=[])
    assert "| paper (JERK) | ours − paper |" in text
    for level, score in theirs.items():
        assert f"| {level} | {score + 100:,.1f} |" in text and f"| {score:,.1f} | 100.0 |" in text
    assert f"own JERK aggregate over its 11 test levels: {paper.aggregates['JERK'][0]:,.1f}" in text


@needs_paper
def test_an_agent_the_paper_did_not_run_gets_its_aggregates_instead() -> None:
    text = render_report(as_summary("random", {"SonicTheHedgehog-Genesis/GreenHillZone.Act2": 500.0}), paper, plots=[])
    assert "paper (" not in text and "did not run 'random'" in text and "Rainbow 2,748.6" in text


@needs_paper
def test_the_scores_plot_draws_ours_beside_the_papers() -> None:
    levels = sorted(paper.levels["JERK"])
    series = {"jerk": {lv: s for lv, (s, _) in paper.levels["Rainbow"].items()},
              "paper (JERK)": {lv: s for lv, (s, _) in paper.levels["JERK"].items()}}
    with Image.open(io.BytesIO(plots.score_bars(series, levels, "test"))) as image:
        assert image.format == "PNG" and image.size[1] > 400  # 11 levels of two bars each


def test_without_the_paper_the_report_says_so(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv(PAPER_ENV, str(tmp_path))  # a folder without test-scores.csv
    assert find_paper_dir() is None and load_paper() is None
    text = render_report(as_summary("jerk", {"SonicTheHedgehog-Genesis/GreenHillZone.Act2": 5.0}), None, plots=[])
    assert "The paper's scores were not found" in text and "| SonicTheHedgehog-Genesis/GreenHillZone.Act2 | 5.0 |" in text


def test_a_benchmark_the_paper_did_not_score_says_nothing_of_the_paper(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv(PAPER_ENV, str(tmp_path))  # a folder without test-scores.csv
    levels = ["Dasher-Genesis/Zone1.Act2"]
    assert not has_paper_scores(levels) and has_paper_scores(["SonicTheHedgehog-Genesis/GreenHillZone.Act2"])
    text = render_report(as_summary("jerk", dict.fromkeys(levels, 5.0)), None, plots=[],
                         paper_levels=has_paper_scores(levels))
    assert "paper" not in text.lower() and "| Dasher-Genesis/Zone1.Act2 | 5.0 |" in text


def test_a_damaged_paper_file_is_treated_as_absent(tmp_path, monkeypatch) -> None:
    (tmp_path / "test-scores.csv").write_bytes(b"agent,game\n\xff\xfe\x00garbage")
    monkeypatch.setenv(PAPER_ENV, str(tmp_path))
    assert load_paper() is None


@needs_paper
@pytest.mark.parametrize(("ours", "theirs"), [("jerk", "JERK"), ("my_agents.py:ppo", "PPO"), ("pkg.mod:Rainbow", "Rainbow"),
                                              ("random", None), ("pkg.mod:random", None)])
def test_our_agents_are_matched_to_the_papers_by_name(ours, theirs) -> None:
    assert paper.agent(ours) == theirs


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
