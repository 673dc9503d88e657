"""Several agents on one benchmark, side by side: ``retrokit evaluate --agent A --agent B`` and the demo.

Each agent is evaluated into ``OUT/<agent>/`` (a full run folder, resumable on
its own); then ``OUT/report.md`` puts their level scores, final scores and
aggregates side by side (on the paper's levels, each beside the paper's
column for it, and all in the paper's Table 1), ``OUT/scores.png`` draws the
scores and ``OUT/mean-learning-curve.png`` their learning curves together. An
agent whose levels fail does not stop the others; the comparison is written
with what finished.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from pathlib import Path

from retrokit.benchmark import plots
from retrokit.benchmark.evaluation import Evaluation, failure_message, run_evaluation
from retrokit.benchmark.paper import PaperScores, has_paper_scores, load_paper
from retrokit.benchmark.report import SCORE_WORDS, number, paper_column, paper_means, table_one
from retrokit.benchmark.rundir import RUN_FILE
from retrokit.benchmark.scores import FROM_UNFINISHED, UNFINISHED_NOTE, Summary
from retrokit.errors import AgentError, FileConflictError, InvalidArgumentError
from retrokit.paths import atomic_write

COMPARISON_FILES = ("report.md", "scores.png", "mean-learning-curve.png")


def agent_folders(agents: list[str]) -> dict[str, str]:
    """Each agent's folder name under ``OUT``: ``jerk``, or ``ppo`` for ``my_agents.py:ppo``; unique.

    Raises:
        InvalidArgumentError: An agent is named twice.
    """
    if len(set(agents)) != len(agents):
        twice = sorted({a for a in agents if agents.count(a) > 1})
        raise InvalidArgumentError(f"Expected each --agent once, got {', '.join(twice)} more than once.")
    folders: dict[str, str] = {}
    for agent in agents:
        base = re.sub(r"[^A-Za-z0-9._-]+", "_", agent.rpartition(":")[2]).strip("._") or "agent"
        name, n = base, 1
        while name in folders.values():
            n += 1
            name = f"{base}-{n}"
        folders[agent] = name
    return folders


def compare(make: Callable[[str, Path], Evaluation], agents: list[str], out: Path, *, resume: bool = False,
            announce: Callable[[str], None] | None = None) -> dict[str, Summary]:
    """Evaluate each agent into ``out/<agent>/`` and write the side-by-side report; return the summaries.

    Args:
        make: The evaluation of an agent into a folder.
        agents: The agents, in the report's order.
        out: The folder of the comparison.
        resume: Continue an interrupted comparison (each agent's folder is resumed; an agent whose turn had
            not come starts).
        announce: Called with a line before each agent's evaluation.

    Raises:
        FileConflictError: ``out`` already holds a comparison, and ``resume`` is not set.
        AgentError: Some agent's levels failed; everything that finished is written.
    """
    folders = agent_folders(agents)
    evaluations = {agent: make(agent, out / folders[agent]) for agent in agents}
    for evaluation in evaluations.values():
        if resume and not os.path.lexists(evaluation.out / RUN_FILE):
            evaluation.resume = False  # the interruption came before this agent's turn: it starts now
        evaluation.check()  # every agent's arguments, before anything is made or played
    there = [name for name in COMPARISON_FILES if (out / name).exists()]
    if there and not resume:
        raise FileConflictError(
            f"Expected a new or empty --out folder, but {out} already holds a comparison ({', '.join(there)}); "
            "continue it with --resume, or choose another --out."
        )
    summaries: dict[str, Summary] = {}
    for agent, evaluation in evaluations.items():
        if announce is not None:
            announce(f"{agent} on the {evaluation.benchmark.name} benchmark ({len(evaluation.levels)} levels):")
        summaries[agent] = run_evaluation(evaluation)
    first = next(iter(evaluations.values()))
    names = [level.name for level in first.levels]
    title = f"{' against '.join(agents)} on {first.benchmark.name}"
    series = {agent: {lv: e.mean_score for lv, e in s.levels.items()} for agent, s in summaries.items()}
    atomic_write(out / "scores.png", plots.score_bars(series, names, f"{title}: level scores"), overwrite=True)
    curves = {agent: s.curve for agent, s in summaries.items() if s.curve}
    budget = next(iter(summaries.values())).budget
    atomic_write(out / "mean-learning-curve.png", plots.mean_learning_curve(curves, budget, title),
                 overwrite=True)
    paper = load_paper(first.paper_dir) if has_paper_scores(names) else None
    text = render_comparison(summaries, folders, names, title, {a: e.failed for a, e in evaluations.items()},
                             paper, paper_levels=has_paper_scores(names))
    atomic_write(out / "report.md", text.encode(), overwrite=True)
    failed = [agent for agent, evaluation in evaluations.items() if evaluation.failed]
    if failed:
        raise AgentError(f"Agent {failed[0]!r}: {failure_message(evaluations[failed[0]])}"
                         + (f" ({len(failed) - 1} more agent(s) failed: see {out / 'report.md'})" if failed[1:] else ""))
    return summaries


def render_comparison(summaries: dict[str, Summary], folders: dict[str, str], levels: list[str], title: str,
                      failed: dict[str, dict[str, str]], paper: PaperScores | None = None, *,
                      paper_levels: bool = False) -> str:
    """``OUT/report.md``: each level's score and final score for each agent (on the paper's levels, each beside
    the paper's column for it), the aggregates, the paper's Table 1, and where each run's own report is."""
    agents = list(summaries)
    first = summaries[agents[0]]
    lines = [f"# {title}", "", f"{first.budget:,} timesteps per level, seed {first.seed}. {SCORE_WORDS}", ""]
    if any(e.scored_from == FROM_UNFINISHED for s in summaries.values() for e in s.levels.values()):
        lines += [f"{UNFINISHED_NOTE} Such scores are marked *.", ""]
    lines += ["## Scores", "", *_side_by_side(summaries, levels, failed, paper, final=False),
              "## Final scores", "", *_side_by_side(summaries, levels, failed, paper, final=True)]
    incomplete = [agent for agent, s in summaries.items() if not s.complete]
    if incomplete:
        lines += [(f"Not complete: {', '.join(incomplete)} (an aggregate covers only its finished levels; finish "
                   "them with --resume)."), ""]
    if paper_levels:
        if paper is None:
            lines += ["The paper's scores were not found, so they are not shown.", ""]
        else:
            lines += [paper.source, "", *table_one(paper, summaries)]
    lines += ["Each agent's own report, summary and plots: "
              + ", ".join(f"[{agent}]({folders[agent]}/report.md)" for agent in agents) + ".", "",
              "![scores](scores.png)", "", "![mean learning curve](mean-learning-curve.png)", ""]
    return "\n".join(lines)


def _side_by_side(summaries: dict[str, Summary], levels: list[str], failed: dict[str, dict[str, str]],
                  paper: PaperScores | None, *, final: bool) -> list[str]:
    """A table of each agent's score (or final score) per level, each agent followed by the paper's column for it."""
    columns: list[tuple[str, str, str | None]] = []  # (header, agent, the paper's agent for a paper column)
    for agent, summary in summaries.items():
        columns.append((agent, agent, None))
        name, theirs = paper_column(summary, paper)
        if name is not None and any(level in theirs for level in levels) and all(c[2] != name for c in columns):
            columns.append((f"{name} (paper)", agent, name))
    lines = ["| level | " + " | ".join(c[0] for c in columns) + " |", "|---|" + "---:|" * len(columns)]
    for level in levels:
        cells = []
        for _, agent, name in columns:
            if name is not None and paper is not None:
                entry = paper.levels[name].get(level)
                cells.append(number(entry and (entry.final if final else entry.score)))
                continue
            entry = summaries[agent].levels.get(level)
            if entry is None:
                cells.append("failed" if level in failed.get(agent, {}) else "–")
            else:
                value = entry.final_score if final and entry.final_score is not None else entry.mean_score
                cells.append(number(value) + (" *" if entry.scored_from == FROM_UNFINISHED else ""))
        lines.append(f"| {level} | " + " | ".join(cells) + " |")
    aggregates = []
    for _, agent, name in columns:
        if name is not None and paper is not None:
            aggregates.append(number(paper_means(paper.levels[name], levels)[1 if final else 0]))
        else:
            value = summaries[agent].final_aggregate if final else summaries[agent].aggregate
            aggregates.append("–" if value is None else f"**{number(value)}**")
    return [*lines, "| **aggregate** | " + " | ".join(aggregates) + " |", ""]
