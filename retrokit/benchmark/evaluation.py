"""An evaluation from start to end: check, run the levels, write every output.

:func:`evaluate` is what ``retrokit evaluate`` runs. It checks the levels, the
ROMs and the agent before playing anything, then runs the levels on a backend
with a progress bar per level, logs the episodes as they come, and writes
``summary.json``, ``summary.csv``, ``report.md`` and the plots, also when a
level fails or the run is interrupted: the results so far are kept, and
``--resume`` finishes the rest.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from retrokit.benchmark import plots
from retrokit.benchmark.agents import resolve_agent
from retrokit.benchmark.definition import Benchmark, Level
from retrokit.benchmark.level import LevelTask, Message
from retrokit.benchmark.paper import PaperScores, load_paper
from retrokit.benchmark.report import paper_column, render_report, write_report, write_summary
from retrokit.benchmark.rundir import RunDir
from retrokit.benchmark.scores import summarize
from retrokit.errors import AgentError, InvalidArgumentError, install_extra
from retrokit.paths import atomic_write

BACKENDS = ("local", "ray")


@dataclass
class Evaluation:
    """Everything one evaluation needs.

    Attributes:
        benchmark: The benchmark.
        levels: The levels to play (from :meth:`Benchmark.select`).
        agent: ``random``, ``jerk`` or ``MODULE:CALLABLE``.
        out: The run folder.
        budget: Timesteps per level (default: the benchmark's).
        seed: The run's seed; each level's own seed derives from it and the level's name.
        workers: Processes (or Ray CPUs) to use.
        backend: ``local`` or ``ray``.
        ray_address: An existing Ray cluster, for the ray backend.
        resume: Continue the evaluation ``out`` holds.
        gif: Save a GIF of the best episode of each level (``gifs/``).
        progress: Show progress bars.
        paper_dir: Where the paper's ``test-scores.csv`` is (default: found by :mod:`.paper`).
    """

    benchmark: Benchmark
    levels: list[Level]
    agent: str
    out: Path
    budget: int | None = None
    seed: int = 0
    workers: int = 1
    backend: str = "local"
    ray_address: str | None = None
    resume: bool = False
    gif: bool = False
    progress: bool = True
    paper_dir: Path | None = None
    failed: dict[str, str] = field(default_factory=dict)

    def settings(self) -> dict[str, Any]:
        """What determines the results; ``--resume`` requires the same."""
        return {
            "benchmark": self.benchmark.as_dict(),
            "agent": self.agent,
            "seed": self.seed,
            "budget": self.budget or self.benchmark.budget,
            "levels": [level.name for level in self.levels],
        }


def evaluate(evaluation: Evaluation) -> dict[str, Any]:
    """Run an evaluation and write its outputs; return the summary.

    Raises:
        AgentError: A level failed (the agent raised or gave an invalid action); the
            other levels' results are written, and ``--resume`` retries the failed ones.
        KeyboardInterrupt: The run was interrupted; what was finished is written.
    """
    ev = evaluation
    if ev.backend not in BACKENDS:
        raise InvalidArgumentError(f"Expected --backend local or ray, got {ev.backend!r}.")
    if ev.workers < 1 or (ev.budget is not None and ev.budget < 1):
        raise InvalidArgumentError(f"Expected --workers and --timesteps of 1 or more, got {ev.workers} and {ev.budget}.")
    ev.benchmark.check_levels(ev.levels)
    resolve_agent(ev.agent)  # an unknown agent fails here, before anything is written
    settings = ev.settings()
    run = RunDir(ev.out, settings, resume=ev.resume)
    budget = settings["budget"]
    tasks = [LevelTask(ev.benchmark, level, ev.agent, budget, ev.seed, ev.gif)
             for level in ev.levels if level.name not in run.finished]
    bars = _progress_bars(ev, run, budget)

    def handle(message: Message) -> None:
        if message.kind == "episode":
            run.add_episode(message.data)
            if message.level in bars:
                bars[message.level].update(message.data["timesteps"] - bars[message.level].n)
        elif message.kind == "done":
            if "gif" in message.data:
                atomic_write(ev.out / "gifs" / f"{level_file_name(message.level)}.gif", message.data["gif"], overwrite=True)
            run.finish(message.level, message.data["timesteps"])
            if message.level in bars:
                bars[message.level].update(budget - bars[message.level].n)
                bars[message.level].set_postfix_str("done")
        elif message.kind == "failed":
            ev.failed[message.level] = message.data["error"]
            run.fail(message.level, message.data["error"])
            if message.level in bars:
                bars[message.level].set_postfix_str("failed")

    try:
        if tasks:
            if ev.backend == "ray":
                from retrokit.benchmark.ray_backend import run_ray

                run_ray(tasks, handle, ev.workers, ev.ray_address)
            else:
                from retrokit.benchmark.local import run_local

                run_local(tasks, handle, ev.workers)
    finally:
        for bar in bars.values():
            bar.close()
        run.close()
        summary = write_outputs(ev, run, load_paper(ev.paper_dir))
    if ev.failed:
        _level, error = next(iter(ev.failed.items()))
        more = f" ({len(ev.failed) - 1} more level(s) failed: see report.md)" if len(ev.failed) > 1 else ""
        raise AgentError(f"{error}{more} The results so far are in {ev.out}; fix the cause and add --resume.")
    return summary


def _progress_bars(ev: Evaluation, run: RunDir, budget: int) -> dict[str, Any]:
    from tqdm import tqdm

    width = max(len(level.name) for level in ev.levels)
    bars = {}
    for position, level in enumerate(ev.levels):
        bar = tqdm(total=budget, desc=level.name.ljust(width), unit="step", position=position, leave=True,
                   disable=not ev.progress, dynamic_ncols=True, mininterval=0.5)
        if level.name in run.finished:
            bar.update(budget)
            bar.set_postfix_str("done before")
        bars[level.name] = bar
    return bars


def level_file_name(level: str) -> str:
    """A level's name as a file name (``gifs/<this>.gif``)."""
    return level.replace("/", "_").replace(os.sep, "_")


def write_outputs(ev: Evaluation, run: RunDir, paper: PaperScores | None) -> dict[str, Any]:
    """Write the summary, the report and the plots of what ``run`` holds; return the summary."""
    summary = summarize(run.settings, run.finished, run.episodes)
    write_summary(ev.out, summary, paper)
    written = []
    if plots.have_matplotlib() and summary["levels"]:
        finished = {level: run.episodes.get(level, []) for level in summary["levels"]}
        title = f"{ev.agent} on {ev.benchmark.name}: episode reward against timesteps"
        atomic_write(ev.out / "learning-curves.png", plots.learning_curves(finished, run.settings["budget"], title),
                     overwrite=True)
        name, theirs = paper_column(summary, paper)
        series = {ev.agent: {level: entry["mean_score"] for level, entry in summary["levels"].items()}}
        if name is not None and any(level in theirs for level in summary["levels"]):
            series[f"paper ({name})"] = {level: score for level, (score, _) in theirs.items()}
        atomic_write(ev.out / "scores.png",
                     plots.score_bars(series, list(summary["levels"]), f"{ev.agent} on {ev.benchmark.name}: level scores"),
                     overwrite=True)
        written = ["learning-curves.png", "scores.png"]
    text = render_report(summary, paper, plots=written, failed=ev.failed or run.failed,
                         env_rules=ev.benchmark.env_options())
    if not plots.have_matplotlib():
        text += f"\nNo plots: matplotlib is not installed (`{install_extra('plot')}`).\n"
    write_report(ev.out, text)
    return summary
