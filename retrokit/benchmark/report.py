"""The files a user reads: ``summary.json``, ``summary.csv`` and ``report.md``.

On levels the paper scored (the Sonic benchmark's test levels), ``report.md``
sets the run beside the paper: its per-level table beside the paper's table of
the same agent (Appendix C's Tables 2 to 6: score and final score), and its
aggregates among the paper's Table 1, which :func:`table_one` writes for the
side-by-side report of several agents too (:mod:`.comparison`).
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path
from typing import Any

from retrokit.benchmark.paper import PAPER_ENV, PAPER_LEVELS, PaperEntry, PaperScores
from retrokit.benchmark.scores import FINAL_SCORE_NOTE, FROM_UNFINISHED, Summary
from retrokit.paths import atomic_write

COLUMNS = ("level", "mean_score", "std", "episodes", "timesteps", "best", "final_score", "final_episodes",
           "paper_score", "paper_sd", "paper_final_score", "paper_final_sd")
SCORE_WORDS = ("The score of a level is the mean total reward of its finished episodes; the aggregate is the mean "
               f"of the level scores. {FINAL_SCORE_NOTE} The final aggregate is the mean of the final scores.")


def paper_column(summary: Summary, paper: PaperScores | None) -> tuple[str | None, dict[str, PaperEntry]]:
    """The paper's name for the summary's agent and its per-level scores, when the paper ran it."""
    name = summary.paper_agent if paper is not None and summary.paper_agent in paper.levels else None
    return name, (paper.levels[name] if paper is not None and name is not None else {})


def write_summary(folder: Path, summary: Summary, paper: PaperScores | None) -> None:
    """Write ``summary.json`` and ``summary.csv`` (replacing the run's own earlier ones)."""
    # allow_nan=False: every number was checked finite on its way in; a NaN would make the file invalid JSON.
    text = json.dumps(summary.as_dict(), indent=1, allow_nan=False)
    atomic_write(folder / "summary.json", (text + "\n").encode(), overwrite=True)
    _, theirs = paper_column(summary, paper)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(COLUMNS)
    for level, entry in summary.levels.items():
        row = theirs.get(level, (None, None, None, None))
        writer.writerow([level, *(_cell(getattr(entry, k)) for k in COLUMNS[1:8]), *map(_cell, row)])
    writer.writerow(["aggregate", _cell(summary.aggregate), "", "", "", "", _cell(summary.final_aggregate),
                     "", "", "", "", ""])
    atomic_write(folder / "summary.csv", out.getvalue().encode(), overwrite=True)


def _cell(value: Any) -> str:
    if value is None:
        return ""
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def number(value: float | None, digits: int = 1) -> str:
    """A score as the reports write it: ``1,234.5``, or ``–`` for none."""
    return "–" if value is None else f"{value:,.{digits}f}"


def _mean(values: list[float]) -> float | None:
    return math.fsum(values) / len(values) if values else None


def paper_means(theirs: dict[str, PaperEntry], levels: list[str]) -> tuple[float | None, float | None]:
    """The paper's mean score and mean final score over those of ``levels`` it has (the aggregate row's)."""
    rows = [theirs[level] for level in levels if level in theirs]
    return _mean([r.score for r in rows]), _mean([r.final for r in rows if r.final is not None])


def render_report(summary: Summary, paper: PaperScores | None, *, plots: list[str],
                  failed: dict[str, str] | None = None, env_rules: dict[str, Any] | None = None,
                  paper_levels: bool = True) -> str:
    """``report.md``: the per-level table beside the paper's scores for the same agent, and Table 1.

    Args:
        summary: The run's summary.
        paper: The paper's scores, if found.
        plots: The plot files to show.
        failed: The levels that failed, with why.
        env_rules: The benchmark's env options, to state.
        paper_levels: Whether any level of the run is one the paper scored (else nothing is said of the paper).
    """
    name, theirs = paper_column(summary, paper)
    if not any(level in theirs for level in summary.levels):
        theirs = {}  # no level to compare: no paper column, and the notes say why
    lines = [
        f"# {summary.agent} on the {summary.benchmark} benchmark",
        "",
        f"{len(summary.levels)} level(s) finished{'' if summary.complete else ' (the run is not complete)'}, "
        f"{summary.budget:,} timesteps each, seed {summary.seed}."
        + (f" Env rules: {', '.join(f'{k}={v}' for k, v in env_rules.items())}." if env_rules else ""),
        SCORE_WORDS,
        *(f"{note} Such levels are marked * below." for note in summary.notes),
        "",
    ]
    if theirs and paper is not None and name is not None:
        lines += [f"## Per level, beside the paper's Table {paper.table(name)} ({name})", ""]
    header = "| level | mean score | sd | final score | episodes | timesteps | best |"
    rule = "|---|---:|---:|---:|---:|---:|---:|"
    if theirs:
        header += f" paper ({name}) | paper final score | ours − paper |"
        rule += "---:|---:|---:|"
    lines += [header, rule]
    for level, e in summary.levels.items():
        mark = " *" if e.scored_from == FROM_UNFINISHED else ""
        row = (f"| {level}{mark} | {number(e.mean_score)} | {number(e.std)} | {number(e.final_score)} | "
               f"{e.episodes} | {e.timesteps:,} | {number(e.best)} |")
        if theirs:
            entry = theirs.get(level)
            diff = None if entry is None else e.mean_score - entry.score
            row += (f" {number(entry and entry.score)} | {number(entry and entry.final)} | {number(diff)} |")
        lines.append(row)
    aggregate = f"| **aggregate** | **{number(summary.aggregate)}** | | **{number(summary.final_aggregate)}** | | | |"
    if theirs:
        score, final = paper_means(theirs, list(summary.levels))
        aggregate += f" {number(score)} | {number(final)} | |"
    lines += [aggregate, ""]
    if paper_levels:
        lines += _paper_notes(summary, paper, name, theirs)
        if paper is not None:
            lines += table_one(paper, {summary.agent: summary})
    if failed:
        lines += ["## Levels that failed", "", *(f"- {level}: {error}" for level, error in failed.items()),
                  "", "Fix the cause and run the same command with `--resume` to finish them.", ""]
    if plots:
        lines += ["## Plots", "", *(f"![{Path(p).stem}]({p})" for p in plots), ""]
    return "\n".join(lines)


def _paper_notes(summary: Summary, paper: PaperScores | None, name: str | None,
                 theirs: dict[str, PaperEntry]) -> list[str]:
    if paper is None:
        return [(f"The paper's scores were not found (${PAPER_ENV} names a folder without a readable "
                 "test-scores.csv, or retrokit's copy is damaged), so they are not shown."), ""]
    if name is None:
        return [paper.source, f"The paper did not run {summary.agent!r}: Table 1 below lists it after the paper's agents.",
                ""]
    compared = sum(1 for level in summary.levels if level in theirs)
    if not compared:
        return [paper.source, (f"None of these levels is among the paper's test levels, so there is no paper column; "
                f"its {name} aggregate over its 11 test levels is in Table 1 below."), ""]
    return [paper.source, f"{compared} of these levels have a paper score; the paper columns' aggregates are their means.",
            ""]


def table_one(paper: PaperScores, summaries: dict[str, Summary]) -> list[str]:
    """The paper's Table 1 (each agent's aggregate over its 11 test levels), each of ours under the paper's row for it.

    Our rows average our scores on the paper's test levels only; a run that finished fewer says how many. Agents
    the paper did not run come last.
    """
    lines = ["## Beside the paper's Table 1", "",
             "| agent | score | sd | final score | final sd |", "|---|---:|---:|---:|---:|"]
    placed: set[str] = set()
    for name, entry in paper.aggregates.items():
        lines.append(f"| {name} (paper) | {number(entry.score)} | {number(entry.sd)} | {number(entry.final)} | "
                     f"{number(entry.final_sd)} |")
        for agent, summary in summaries.items():
            if summary.paper_agent == name:
                lines.append(_our_row(agent, summary))
                placed.add(agent)
    lines += [_our_row(agent, summary) for agent, summary in summaries.items() if agent not in placed]
    return [*lines, "", ("The paper's standard deviations are over its several runs of each agent; a run of ours is "
                         "one run, so it has none."), ""]


def _our_row(agent: str, summary: Summary) -> str:
    ours = [e for level, e in summary.levels.items() if level in PAPER_LEVELS]
    score = _mean([e.mean_score for e in ours])
    final = _mean([e.mean_score if e.final_score is None else e.final_score for e in ours])
    count = "" if len(ours) == len(PAPER_LEVELS) else f", {len(ours)} of the {len(PAPER_LEVELS)} levels"
    return f"| **{agent}** (this run{count}) | **{number(score)}** | – | **{number(final)}** | – |"


def write_report(folder: Path, text: str) -> None:
    """Write ``report.md``."""
    atomic_write(folder / "report.md", text.encode(), overwrite=True)
