"""An evaluation from start to end: check, run the levels, write every output.

:func:`evaluate` is what ``retrokit evaluate`` runs. It checks every argument,
the levels, the ROMs and the agent before it makes anything, then runs the
levels on a backend (each level in a worker process of its own, watched for
stalls), shows their progress, logs the episodes as they come, and writes
``summary.json``, ``summary.csv``, ``report.md`` and the plots, also when a
level fails or the run is interrupted: the results so far are kept, and
``--resume`` finishes the rest.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from retrokit.benchmark import plots
from retrokit.benchmark.agents import check_agent
from retrokit.benchmark.definition import Benchmark, Level
from retrokit.benchmark.level import (
    EpisodeEnded,
    LevelDone,
    LevelFailed,
    LevelRestarted,
    LevelTask,
    Message,
    Progress,
)
from retrokit.benchmark.paper import PaperScores, has_paper_scores, load_paper
from retrokit.benchmark.progress import LevelProgress
from retrokit.benchmark.report import paper_column, render_report, write_report, write_summary
from retrokit.benchmark.rundir import RunDir
from retrokit.benchmark.scores import Summary, level_score, summarize
from retrokit.benchmark.speed import Speed
from retrokit.benchmark.watchdog import DEFAULT_STALL_SECONDS, Watchdog
from retrokit.envs.vector import available_cpus
from retrokit.errors import AgentError, InvalidArgumentError
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
        progress: Show progress (bars on a terminal, else a line per level).
        paper_dir: Where the paper's ``test-scores.csv`` is (default: found by :mod:`.paper`).
        stall_timeout: Seconds a level may go without a timestep before it is stopped and fails.
        setup: A built-in learning agent's setup (:class:`retrokit.learning.setup.LearnerSetup`): given to the
            agent on each level, its observation options added to the level's env, its ``settings()`` recorded.
        failed: The levels that failed in this run, with why (filled by :func:`evaluate`).
        played: The levels finished in this run: their timesteps and play seconds (filled by :func:`evaluate`).
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
    stall_timeout: float = DEFAULT_STALL_SECONDS
    setup: Any = None
    failed: dict[str, str] = field(default_factory=dict)
    played: dict[str, tuple[int, float]] = field(default_factory=dict)

    def check(self) -> None:
        """Check the arguments, the levels, the ROMs and the agent; nothing is made before this passes.

        Raises:
            InvalidArgumentError: A number is out of range, or an option does not fit the backend.
            RetrokitError: A level, ROM or agent cannot be found (see :meth:`Benchmark.check_levels`).
        """
        from retrokit.benchmark.local import refuse_inside_a_worker

        refuse_inside_a_worker()
        if self.backend not in BACKENDS:
            raise InvalidArgumentError(f"Expected --backend local or ray, got {self.backend!r}.")
        if self.workers < 1:
            raise InvalidArgumentError(f"Expected --workers of 1 or more, got {self.workers}.")
        if self.budget is not None and self.budget < 1:
            raise InvalidArgumentError(f"Expected --timesteps of 1 or more, got {self.budget}.")
        if self.seed < 0:
            raise InvalidArgumentError(f"Expected a --seed of 0 or more, got {self.seed}.")
        if not (math.isfinite(self.stall_timeout) and self.stall_timeout > 0):
            raise InvalidArgumentError(f"Expected a --stall-timeout of more than 0 seconds, got {self.stall_timeout}.")
        if self.ray_address is not None and self.backend != "ray":
            raise InvalidArgumentError(f"Expected --backend ray with --ray-address, got --backend {self.backend}.")
        if self.gif and self.setup is not None:
            raise InvalidArgumentError(
                f"Expected no --gif with the learning agent {self.agent}: it sees gray frame stacks, not the screen "
                "a GIF shows; drop --gif."
            )
        self.benchmark.check_levels(self.levels)
        check_agent(self.agent)  # in a child: an agent module that exits at import must not end this process

    def settings(self) -> dict[str, Any]:
        """What determines the results; ``--resume`` requires the same."""
        return {
            "benchmark": self.benchmark.as_dict(),
            "agent": self.agent,
            "seed": self.seed,
            "budget": self.budget or self.benchmark.budget,
            "levels": [level.name for level in self.levels],
            **({"agent_setup": self.setup.settings()} if self.setup is not None else {}),
        }

    def speed(self) -> Speed | None:
        """How fast this run's levels played (``None`` if it finished none, as a resume of a finished run)."""
        if not self.played:
            return None
        return Speed(sum(steps for steps, _ in self.played.values()), sum(s for _, s in self.played.values()),
                     self.workers, min(self.workers, len(self.played) + len(self.failed)), available_cpus())


def evaluate(evaluation: Evaluation) -> Summary:
    """Run an evaluation and write its outputs; return the summary.

    Raises:
        AgentError: A level failed (the agent raised, stalled, returned early or ended its process); the
            other levels' results are written, and ``--resume`` plays the failed ones again.
        KeyboardInterrupt: The run was interrupted; what was finished is written.
    """
    summary = run_evaluation(evaluation)
    if evaluation.failed:
        raise AgentError(failure_message(evaluation))
    return summary


def failure_message(ev: Evaluation) -> str:
    """One line on the levels that failed in ``ev``, and how to finish them."""
    _level, error = next(iter(ev.failed.items()))
    more = f" ({len(ev.failed) - 1} more level(s) failed: see report.md)" if len(ev.failed) > 1 else ""
    return f"{error}{more} The results so far are in {ev.out}; fix the cause and add --resume."


def run_evaluation(evaluation: Evaluation) -> Summary:
    """Like :func:`evaluate`, but a level that fails is only noted in ``evaluation.failed``."""
    ev = evaluation
    ev.check()
    settings = ev.settings()
    budget = settings["budget"]
    run = RunDir(ev.out, settings, resume=ev.resume)
    try:
        tasks = [LevelTask(ev.benchmark, level, ev.agent, budget, ev.seed, ev.gif, ev.setup)
                 for level in ev.levels if level.name not in run.finished]
        progress = LevelProgress([level.name for level in ev.levels], budget, set(run.finished), show=ev.progress)
        try:
            _run(ev, tasks, run, progress, budget)
        finally:
            progress.close()
    finally:
        try:
            summary = write_outputs(ev, run, load_paper(ev.paper_dir))
        finally:
            run.close()  # the folder stays locked until its outputs are written
    return summary


def _run(ev: Evaluation, tasks: list[LevelTask], run: RunDir, progress: LevelProgress, budget: int) -> None:
    """Play ``tasks`` on the evaluation's backend, recording every message in ``run``."""

    def handle(message: Message) -> None:
        if isinstance(message, Progress):
            progress.step(message.level, message.timesteps)
        elif isinstance(message, EpisodeEnded):
            run.add_episode(message.level, message.episode)
            progress.step(message.level, message.episode.timesteps)
        elif isinstance(message, LevelDone):
            if message.gif is not None:
                atomic_write(ev.out / "gifs" / f"{level_file_name(message.level)}.gif", message.gif, overwrite=True)
            run.finish(message.level, message.timesteps, message.unfinished_reward)
            ev.played[message.level] = (message.timesteps, message.seconds)
            score = level_score(run.episodes.get(message.level, []), run.finished[message.level])
            progress.end(message.level, f"done, {score.episodes} episode(s), score {score.mean_score:,.1f}")
        elif isinstance(message, LevelRestarted):
            run.restart(message.level)
            progress.restart(message.level, message.reason)
        elif isinstance(message, LevelFailed):
            ev.failed[message.level] = message.error
            run.fail(message.level, message.error)
            progress.end(message.level, f"failed: {message.error}")

    if not tasks:
        return
    watchdog = Watchdog(ev.stall_timeout, budget)
    if ev.backend == "ray":
        from retrokit.benchmark.ray_backend import run_ray

        run_ray(tasks, handle, ev.workers, ev.ray_address, watchdog)
    else:
        from retrokit.benchmark.local import run_local

        run_local(tasks, handle, ev.workers, watchdog)


def level_file_name(level: str) -> str:
    """A level's name as a file name (``gifs/<this>.gif``)."""
    return level.replace("/", "_").replace(os.sep, "_")


def write_outputs(ev: Evaluation, run: RunDir, paper: PaperScores | None) -> Summary:
    """Write the summary, the report and the plots of what ``run`` holds; return the summary."""
    summary = summarize(run.settings, run.finished, run.episodes)
    write_summary(ev.out, summary, paper)
    written = []
    if summary.levels:
        finished = {level: run.episodes.get(level, []) for level in summary.levels}
        title = f"{ev.agent} on {ev.benchmark.name}: episode reward against timesteps"
        atomic_write(ev.out / "learning-curves.png", plots.learning_curves(finished, run.settings["budget"], title),
                     overwrite=True)
        name, theirs = paper_column(summary, paper)
        series: dict[str, dict[str, float | None]] = {
            ev.agent: {level: entry.mean_score for level, entry in summary.levels.items()}}
        if name is not None and any(level in theirs for level in summary.levels):
            series[f"paper ({name})"] = {level: entry.score for level, entry in theirs.items()}
        atomic_write(ev.out / "scores.png",
                     plots.score_bars(series, list(summary.levels), f"{ev.agent} on {ev.benchmark.name}: level scores"),
                     overwrite=True)
        atomic_write(ev.out / "mean-learning-curve.png",
                     plots.mean_learning_curve({ev.agent: summary.curve}, summary.budget,
                                               f"{ev.agent} on {ev.benchmark.name}: learning curve"), overwrite=True)
        written = ["learning-curves.png", "scores.png", "mean-learning-curve.png"]
    text = render_report(summary, paper, plots=written, failed=ev.failed or run.failed,
                         env_rules=ev.benchmark.env_options(),
                         paper_levels=has_paper_scores(level.name for level in ev.levels))
    write_report(ev.out, text)
    return summary
