"""The report and plots beside the paper's scores, exercised with the paper's own numbers."""

from __future__ import annotations

import io

import pytest
from PIL import Image

from retrokit.benchmark import plots
from retrokit.benchmark.definition import load_benchmark
from retrokit.benchmark.paper import PAPER_ENV, find_paper_dir, has_paper_scores, load_paper
from retrokit.benchmark.report import render_report
from retrokit.benchmark.scores import LevelScore, Summary, aggregate

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
