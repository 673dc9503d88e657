"""The files a user reads: ``summary.json``, ``summary.csv`` and ``report.md``."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path
from typing import Any

from retrokit.benchmark.paper import PAPER_ENV, PaperScores
from retrokit.benchmark.scores import FROM_UNFINISHED, Summary
from retrokit.paths import atomic_write

COLUMNS = ("level", "mean_score", "std", "episodes", "timesteps", "best", "paper_score", "paper_sd")


def paper_column(summary: Summary, paper: PaperScores | None) -> tuple[str | None, dict[str, tuple[float, float]]]:
    """The paper's name for the summary's agent and its per-level scores, when the paper ran it."""
    name = paper.agent(summary.agent) if paper is not None else None
    return name, (paper.levels.get(name, {}) if paper is not None and name is not None else {})


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
        score, sd = theirs.get(level, (None, None))
        writer.writerow([level, *(_cell(getattr(entry, k)) for k in COLUMNS[1:6]), _cell(score), _cell(sd)])
    writer.writerow(["aggregate", _cell(summary.aggregate), "", "", "", "", "", ""])
    atomic_write(folder / "summary.csv", out.getvalue().encode(), overwrite=True)


def _cell(value: Any) -> str:
    if value is None:
        return ""
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def _number(value: float | None, digits: int = 1) -> str:
    return "–" if value is None else f"{value:,.{digits}f}"


def render_report(summary: Summary, paper: PaperScores | None, *, plots: list[str],
                  failed: dict[str, str] | None = None, env_rules: dict[str, Any] | None = None,
                  paper_levels: bool = True) -> str:
    """``report.md``: the per-level table beside the paper's scores for the same agent.

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
        ("The score of a level is the mean total reward of its finished episodes; the aggregate is the mean "
        "of the level scores."),
        *(f"{note} Such levels are marked * below." for note in summary.notes),
        "",
    ]
    header = "| level | mean score | sd | episodes | timesteps | best |"
    rule = "|---|---:|---:|---:|---:|---:|"
    if theirs:
        header += f" paper ({name}) | ours − paper |"
        rule += "---:|---:|"
    lines += [header, rule]
    for level, e in summary.levels.items():
        mark = " *" if e.scored_from == FROM_UNFINISHED else ""
        row = (f"| {level}{mark} | {_number(e.mean_score)} | {_number(e.std)} | {e.episodes} | "
               f"{e.timesteps:,} | {_number(e.best)} |")
        if theirs:
            score = theirs.get(level, (None, None))[0]
            diff = None if score is None else e.mean_score - score
            row += f" {_number(score)} | {_number(diff)} |"
        lines.append(row)
    aggregate = f"| **aggregate** | **{_number(summary.aggregate)}** | | | | |"
    if theirs:
        ours_in_paper = [lv for lv in summary.levels if lv in theirs]
        paper_mean = sum(theirs[lv][0] for lv in ours_in_paper) / len(ours_in_paper) if ours_in_paper else None
        aggregate += f" {_number(paper_mean)} | |"
    lines += [aggregate, ""]
    if paper_levels:
        lines += _paper_notes(summary, paper, name, theirs)
    if failed:
        lines += ["## Levels that failed", "", *(f"- {level}: {error}" for level, error in failed.items()),
                  "", "Fix the cause and run the same command with `--resume` to finish them.", ""]
    if plots:
        lines += ["## Plots", "", *(f"![{Path(p).stem}]({p})" for p in plots), ""]
    return "\n".join(lines)


def _paper_notes(summary: Summary, paper: PaperScores | None, name: str | None,
                 theirs: dict[str, tuple[float, float]]) -> list[str]:
    if paper is None:
        return [(f"The paper's scores were not found (looked in ${PAPER_ENV}, then shared/paper beside the repository "
                "and the folders above it), so they are not shown."), ""]
    source = f"Paper: Nichol et al., *Gotta Learn Fast* (2018), Appendix C, from `{paper.path}`."
    if name is None:
        others = ", ".join(f"{agent} {score:,.1f}" for agent, (score, _) in paper.aggregates.items())
        return [source, f"The paper did not run {summary.agent!r}; its aggregates over its 11 test levels: {others}.", ""]
    compared = sum(1 for level in summary.levels if level in theirs)
    if not compared:
        return [source, (f"None of these levels is among the paper's test levels, so there is no paper column; "
                f"its {name} aggregate over its 11 test levels is {paper.aggregates.get(name, (0.0,))[0]:,.1f}."), ""]
    notes = [source, f"{compared} of these levels have a paper score; the paper column's aggregate is their mean."]
    if name in paper.aggregates:
        notes.append(f"The paper's own {name} aggregate over its 11 test levels: {paper.aggregates[name][0]:,.1f}.")
    return [*notes, ""]


def write_report(folder: Path, text: str) -> None:
    """Write ``report.md``."""
    atomic_write(folder / "report.md", text.encode(), overwrite=True)
