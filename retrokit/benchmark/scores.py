"""The protocol's scores: each level's mean episode reward, and their mean, the aggregate; and the final scores.

The paper averages "the total reward of each episode over all episodes of the
run", and its aggregate averages every test level. A level that spent its
budget without finishing an episode (a budget shorter than an episode) has one
episode in its run, the one under way when the budget ran out: it scores that
episode's reward, so that no level is left out of the aggregate, and the
summary and the report say so.

The paper's tables also give a "Final Score", which its text does not define;
its Figure 3 draws the *instantaneous* score against timesteps (not the mean
over the timesteps so far), and a final score reads as where that curve ends.
So here the instantaneous score at timestep ``t`` is the mean reward of the
episodes that ended in the last tenth of the budget before ``t`` (a window of
timesteps, as the figure's axis and the budget are timesteps; a window of
episodes would span more of the budget where episodes are long), or, when
none ended there, the reward of the last episode that ended before ``t``; the
final score is its value at the end of the budget. At the paper's budgets
(1M timesteps, episodes of at most 4,500) the window holds 22 episodes or more.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

from retrokit.benchmark.monitor import Episode
from retrokit.benchmark.paper import paper_name
from retrokit.benchmark.rundir import FinishedLevel

#: How a level's score was made (``LevelScore.scored_from``).
FROM_EPISODES = "finished episodes"
FROM_UNFINISHED = "unfinished episode"
UNFINISHED_NOTE = ("A level that finished no episode within its budget scores the reward of the episode under way "
                   "when its budget ran out (its run's only episode), so that every level counts in the aggregate.")
#: The share of the budget whose episodes make the final score (and each point of the learning curve).
FINAL_WINDOW = 0.1
#: The points of the mean learning curve (``Summary.curve``).
CURVE_POINTS = 50
FINAL_SCORE_NOTE = ("A level's final score is the mean reward of the episodes that ended in the last 10% of its "
                    "budget's timesteps (or, if none did, of the last episode that ended): where its learning curve ends.")


@dataclass(frozen=True)
class LevelScore:
    """One level's entry of ``summary.json``.

    Attributes:
        mean_score: The mean total reward of its finished episodes (see the module's doc when it has none).
        episodes: Its finished episodes.
        timesteps: The timesteps the agent took on it.
        std: The standard deviation of the episodes' rewards (``None`` without a finished episode).
        best: The best episode's reward (``None`` without a finished episode).
        scored_from: :data:`FROM_EPISODES` or :data:`FROM_UNFINISHED`.
        final_score: The level's final score (see the module's doc); without a finished episode, ``mean_score``.
        final_episodes: The episodes it averages (0 without a finished episode).
    """

    mean_score: float
    episodes: int
    timesteps: int
    std: float | None
    best: float | None
    scored_from: str = FROM_EPISODES
    final_score: float | None = None
    final_episodes: int = 0


@dataclass(frozen=True)
class Summary:
    """``summary.json``: the finished levels' scores, in the order the run names its levels.

    Attributes:
        benchmark: The benchmark's name.
        agent: The agent's name.
        seed: The run's seed.
        budget: Timesteps per level.
        complete: Whether every level of the run finished.
        levels: The finished levels' scores.
        aggregate: The mean of the level scores (``None`` before any level finished).
        notes: How the scores were made, where a reader could not guess it.
        final_aggregate: The mean of the level final scores (``None`` before any level finished).
        paper_agent: The paper's name for the agent (``"Joint PPO"`` for ``ppo`` with ``--init``), if it ran it.
        curve: The mean learning curve: ``{"timesteps": [...], "score": [...]}`` (see :func:`mean_curve`).
    """

    benchmark: str
    agent: str
    seed: int
    budget: int
    complete: bool
    levels: dict[str, LevelScore]
    aggregate: float | None
    notes: list[str] = field(default_factory=list)
    final_aggregate: float | None = None
    paper_agent: str | None = None
    curve: dict[str, list[Any]] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        """The summary as JSON data."""
        return asdict(self)


class Episodes:
    """A level's finished episodes in the order they ended, to read instantaneous scores from.

    Args:
        episodes: The level's finished episodes, in any order.
    """

    def __init__(self, episodes: Sequence[Episode]) -> None:
        ordered = sorted(episodes, key=lambda e: e.episode)
        self.ends = [e.timesteps for e in ordered]
        self.rewards = [e.reward for e in ordered]
        self._sums = [0.0]  # running sums: each window's mean in O(log n), for the curve's many windows
        for reward in self.rewards:
            self._sums.append(self._sums[-1] + reward)

    def instantaneous(self, t: float, width: float) -> tuple[float, int] | None:
        """The instantaneous score at timestep ``t`` and the episodes it averages; ``None`` before any ended.

        The mean reward of the episodes that ended in ``(t - width, t]``, else of the last that ended by ``t``.
        """
        stop = bisect.bisect_right(self.ends, t)
        if stop == 0:
            return None
        start = min(bisect.bisect_right(self.ends, t - width), stop - 1)
        return (self._sums[stop] - self._sums[start]) / (stop - start), stop - start


def level_score(episodes: list[Episode], finished: FinishedLevel) -> LevelScore:
    """A finished level's score and final score, from its finished episodes (or, with none, the one under way)."""
    ended = Episodes(episodes)
    rewards = ended.rewards
    if not rewards:
        reward = finished.unfinished_reward
        return LevelScore(reward, 0, finished.timesteps, None, None, FROM_UNFINISHED, reward, 0)
    mean = math.fsum(rewards) / len(rewards)
    std = math.sqrt(math.fsum((r - mean) ** 2 for r in rewards) / len(rewards))
    final, count = ended.instantaneous(finished.timesteps, FINAL_WINDOW * finished.timesteps) or (mean, 0)
    return LevelScore(mean, len(rewards), finished.timesteps, std, max(rewards), FROM_EPISODES, final, count)


def aggregate(levels: dict[str, LevelScore]) -> float | None:
    """The mean of the level scores: every finished level counts."""
    return math.fsum(entry.mean_score for entry in levels.values()) / len(levels) if levels else None


def final_aggregate(levels: dict[str, LevelScore]) -> float | None:
    """The mean of the level final scores."""
    finals = [entry.mean_score if entry.final_score is None else entry.final_score for entry in levels.values()]
    return math.fsum(finals) / len(finals) if finals else None


def mean_curve(episodes: dict[str, list[Episode]], budget: int, points: int = CURVE_POINTS) -> dict[str, list[Any]]:
    """The paper's Figure 3 for one run: the instantaneous score at evenly spaced timesteps, averaged over levels.

    The levels that finished no episode are left out; the curve starts once each of the others has finished
    one (so that no level joins the mean midway, making a jump), ``None`` before. Its last point is the mean
    of those levels' final scores.
    """
    levels = [Episodes(eps) for eps in episodes.values() if eps]
    steps = sorted({math.ceil(k * budget / points) for k in range(1, points + 1)})
    scores: list[float | None] = []
    for t in steps:
        known = [level.instantaneous(t, FINAL_WINDOW * budget) for level in levels]
        scores.append(None if not levels or None in known else math.fsum(k[0] for k in known) / len(known))
    return {"timesteps": steps, "score": scores}


def paper_agent(settings: dict[str, Any]) -> str | None:
    """The paper's row a run's agent stands beside: a built-in learning agent's setup names it (PPO from scratch,
    Joint PPO from a trained policy, none when it plays zero-shot); any other agent goes by its name."""
    setup = settings.get("agent_setup")
    if isinstance(setup, dict):
        return setup.get("paper_agent")
    return paper_name(settings["agent"])


def summarize(settings: dict[str, Any], finished: dict[str, FinishedLevel],
              episodes: dict[str, list[Episode]]) -> Summary:
    """The summary of the finished levels, in the order the run names them."""
    levels = {
        name: level_score(episodes.get(name, []), finished[name])
        for name in settings["levels"] if name in finished
    }
    notes = [UNFINISHED_NOTE] if any(e.scored_from == FROM_UNFINISHED for e in levels.values()) else []
    curve = mean_curve({name: episodes.get(name, []) for name in levels}, settings["budget"]) if levels else {}
    return Summary(
        benchmark=settings["benchmark"]["name"], agent=settings["agent"], seed=settings["seed"],
        budget=settings["budget"], complete=len(levels) == len(settings["levels"]), levels=levels,
        aggregate=aggregate(levels), notes=notes, final_aggregate=final_aggregate(levels),
        paper_agent=paper_agent(settings), curve=curve,
    )
