"""The protocol's scores: each level's mean episode reward, and their mean, the aggregate."""

from __future__ import annotations

import math
from typing import Any


def level_score(episodes: list[dict[str, Any]], timesteps: int) -> dict[str, Any]:
    """One level's entry of ``summary.json``: the mean of its episodes' total rewards, and more.

    Args:
        episodes: Its finished episodes (``reward`` each), in order.
        timesteps: The timesteps the agent took on it.
    """
    rewards = [float(e["reward"]) for e in sorted(episodes, key=lambda e: e["episode"])]
    if not rewards:
        return {"mean_score": None, "episodes": 0, "timesteps": timesteps, "std": None, "best": None}
    mean = math.fsum(rewards) / len(rewards)
    std = math.sqrt(math.fsum((r - mean) ** 2 for r in rewards) / len(rewards))
    return {"mean_score": mean, "episodes": len(rewards), "timesteps": timesteps, "std": std, "best": max(rewards)}


def aggregate(levels: dict[str, dict[str, Any]]) -> float | None:
    """The mean of the per-level mean scores (levels with no finished episode left out)."""
    scores = [entry["mean_score"] for entry in levels.values() if entry["mean_score"] is not None]
    return math.fsum(scores) / len(scores) if scores else None


def summarize(settings: dict[str, Any], finished: dict[str, dict[str, Any]],
              episodes: dict[str, list[dict[str, Any]]]) -> dict[str, Any]:
    """The contents of ``summary.json`` for the finished levels, in the order the run names them."""
    levels = {
        name: level_score(episodes.get(name, []), finished[name]["timesteps"])
        for name in settings["levels"] if name in finished
    }
    return {
        "benchmark": settings["benchmark"]["name"],
        "agent": settings["agent"],
        "seed": settings["seed"],
        "budget": settings["budget"],
        "complete": len(levels) == len(settings["levels"]),
        "levels": levels,
        "aggregate": aggregate(levels),
    }
