"""The paper's published scores, read from ``test-scores.csv`` (and its README.md).

The file is not part of the package: it is looked for in ``$RETROKIT_PAPER``,
then in a ``shared/paper`` folder beside the repository or any folder above
it (where the project keeps it), then beside the working folder. When it is
nowhere, reports say so and go on without it.
"""

from __future__ import annotations

import csv
import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from retrokit.data.sonic_levels import TEST_LEVELS

PAPER_ENV = "RETROKIT_PAPER"
SCORES_FILE = "test-scores.csv"
#: Our agent names that the paper also ran.
AGENT_NAMES = {"jerk": "JERK"}
#: The levels the paper scored: its 11 test levels.
PAPER_LEVELS = frozenset(f"{game}/{state}" for game, states in TEST_LEVELS.items() for state in states)


def has_paper_scores(levels: Iterable[str]) -> bool:
    """Whether the paper scored any of ``levels`` (else a report says nothing of the paper)."""
    return any(level in PAPER_LEVELS for level in levels)


@dataclass
class PaperScores:
    """The paper's per-level test scores, by agent.

    Attributes:
        path: The CSV file.
        levels: ``{agent: {"Game/State": (score, sd)}}``.
        aggregates: ``{agent: (score, sd)}``.
    """

    path: Path
    levels: dict[str, dict[str, tuple[float, float]]] = field(default_factory=dict)
    aggregates: dict[str, tuple[float, float]] = field(default_factory=dict)

    def agent(self, name: str) -> str | None:
        """The paper's name of our agent ``name``, if the paper ran it.

        Case does not matter, and a user agent ``MODULE:CALLABLE`` goes by its
        callable's name, so ``my_agents.py:ppo`` is compared with the paper's PPO.
        """
        wanted = AGENT_NAMES.get(name, name.rpartition(":")[2]).lower()
        return next((a for a in self.levels if a.lower() == wanted), None)


def find_paper_dir(start: Path | None = None) -> Path | None:
    """The folder that holds ``test-scores.csv``, or ``None``."""
    override = os.environ.get(PAPER_ENV)
    if override:
        return Path(override).expanduser() if (Path(override).expanduser() / SCORES_FILE).is_file() else None
    roots = [Path(__file__).resolve().parents[2], (start or Path.cwd()).resolve()]
    for root in roots:
        for folder in (root, *root.parents):
            candidate = folder / "shared" / "paper"
            if (candidate / SCORES_FILE).is_file():
                return candidate
    return None


def load_paper(folder: Path | None = None) -> PaperScores | None:
    """Read the paper's scores from ``folder`` (default: :func:`find_paper_dir`); ``None`` if absent or unreadable."""
    folder = folder if folder is not None else find_paper_dir()
    if folder is None:
        return None
    path = folder / SCORES_FILE
    scores = PaperScores(path)
    try:
        with path.open(encoding="utf-8", newline="") as f:
            for row in csv.DictReader(f):
                agent, game, state = row["agent"], row["game"], row["state"]
                value = (float(row["score"]), float(row["score_sd"] or 0.0))
                if state == "Aggregate":
                    scores.aggregates[agent] = value
                else:
                    scores.levels.setdefault(agent, {})[f"{game}/{state}"] = value
    except (OSError, KeyError, ValueError, csv.Error):
        return None
    return scores
