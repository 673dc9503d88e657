"""The protocol's scores: each level's mean episode reward, and their mean, the aggregate.

The paper averages "the total reward of each episode over all episodes of the
run", and its aggregate averages every test level. A level that spent its
budget without finishing an episode (a budget shorter than an episode) has one
episode in its run, the one under way when the budget ran out: it scores that
episode's reward, so that no level is left out of the aggregate, and the
summary and the report say so.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

from retrokit.benchmark.monitor import Episode
from retrokit.benchmark.rundir import FinishedLevel

#: How a level's score was made (``LevelScore.scored_from``).
FROM_EPISODES = "finished episodes"
FROM_UNFINISHED = "unfinished episode"
UNFINISHED_NOTE = ("A level that finished no episode within its budget scores the reward of the episode under way "
                   "when its budget ran out (its run's only episode), so that every level counts in the aggregate.")


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
    """

    mean_score: float
    episodes: int
    timesteps: int
    std: float | None
    best: float | None
    scored_from: str = FROM_EPISODES


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
    """

    benchmark: str
    agent: str
    seed: int
    budget: int
    complete: bool
    levels: dict[str, LevelScore]
    aggregate: float | None
    notes: list[str] = field(default_factory=list)

    def as_dict(self) -> dict[str, Any]:
        """The summary as JSON data."""
        return asdict(self)


def level_score(episodes: list[Episode], finished: FinishedLevel) -> LevelScore:
    """A finished level's score, from its finished episodes (or, with none, the one under way)."""
    rewards = [e.reward for e in sorted(episodes, key=lambda e: e.episode)]
    if not rewards:
        return LevelScore(finished.unfinished_reward, 0, finished.timesteps, None, None, FROM_UNFINISHED)
    mean = math.fsum(rewards) / len(rewards)
    std = math.sqrt(math.fsum((r - mean) ** 2 for r in rewards) / len(rewards))
    return LevelScore(mean, len(rewards), finished.timesteps, std, max(rewards))


def aggregate(levels: dict[str, LevelScore]) -> float | None:
    """The mean of the level scores: every finished level counts."""
    return math.fsum(entry.mean_score for entry in levels.values()) / len(levels) if levels else None


def summarize(settings: dict[str, Any], finished: dict[str, FinishedLevel],
              episodes: dict[str, list[Episode]]) -> Summary:
    """The summary of the finished levels, in the order the run names them."""
    levels = {
        name: level_score(episodes.get(name, []), finished[name])
        for name in settings["levels"] if name in finished
    }
    notes = [UNFINISHED_NOTE] if any(e.scored_from == FROM_UNFINISHED for e in levels.values()) else []
    return Summary(
        benchmark=settings["benchmark"]["name"], agent=settings["agent"], seed=settings["seed"],
        budget=settings["budget"], complete=len(levels) == len(settings["levels"]), levels=levels,
        aggregate=aggregate(levels), notes=notes,
    )
