"""The paper's published scores, read from ``test-scores.csv``.

The file ships in the package (``paper_scores/``, whose README.md says what
its columns hold), so an installed retrokit's reports have the paper's
numbers; ``$RETROKIT_PAPER`` names another folder holding a
``test-scores.csv`` to use instead. When the file named is absent or damaged,
reports say so and go on without it.
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

from retrokit.data.sonic_levels import TEST_LEVELS
from retrokit.errors import RetrokitError
from retrokit.paths import read_regular_file

PAPER_ENV = "RETROKIT_PAPER"
SCORES_FILE = "test-scores.csv"
#: The copy that ships with retrokit.
SHIPPED_DIR = Path(__file__).resolve().parent / "paper_scores"
#: Our agents that the paper also ran, by name, and the paper's name for them.
AGENT_NAMES = {"jerk": "JERK", "ppo": "PPO", "rainbow": "Rainbow"}
#: The paper's names of our learning agents when they start from a jointly trained policy (``--init``).
JOINT_NAMES = {"PPO": "Joint PPO", "Rainbow": "Joint Rainbow"}
#: The levels the paper scored: its 11 test levels.
PAPER_LEVELS = frozenset(f"{game}/{state}" for game, states in TEST_LEVELS.items() for state in states)
#: The number of the paper's first per-level table (Appendix C); the agents' tables follow in the file's order.
FIRST_LEVEL_TABLE = 2
#: A larger file is refused (a link to /dev/zero must not fill memory): the paper's is 5 kB.
MAX_SCORES_BYTES = 1 << 20


def has_paper_scores(levels: Iterable[str]) -> bool:
    """Whether the paper scored any of ``levels`` (else a report says nothing of the paper)."""
    return any(level in PAPER_LEVELS for level in levels)


def paper_name(agent: str, init: str | None = None) -> str | None:
    """The paper's name for our agent ``agent`` (run with ``--init init``), or ``None`` if the paper did not run it.

    Case does not matter, and a user agent ``MODULE:CALLABLE`` goes by its
    callable's name, so ``my_agents.py:ppo`` is compared with the paper's PPO.
    A learning agent that starts from a trained policy is the paper's "Joint" one.
    """
    name = AGENT_NAMES.get(agent.rpartition(":")[2].lower())
    return JOINT_NAMES.get(name, name) if init and name is not None else name


class PaperEntry(NamedTuple):
    """One row of the paper's tables: the score and the final score, with their standard deviations.

    The final score and its deviation are ``None`` where the paper gives none (Human).
    """

    score: float
    sd: float
    final: float | None
    final_sd: float | None


@dataclass
class PaperScores:
    """The paper's per-level test scores and aggregates, by agent, in the file's order.

    Attributes:
        path: The CSV file.
        shipped: Whether it is retrokit's own copy (not one named by ``$RETROKIT_PAPER``).
        levels: ``{agent: {"Game/State": entry}}``.
        aggregates: ``{agent: entry}``: the paper's Table 1.
    """

    path: Path
    shipped: bool = True
    levels: dict[str, dict[str, PaperEntry]] = field(default_factory=dict)
    aggregates: dict[str, PaperEntry] = field(default_factory=dict)

    def agent(self, name: str, init: str | None = None) -> str | None:
        """The paper's name of our agent ``name`` (see :func:`paper_name`), if the file has its scores."""
        wanted = paper_name(name, init)
        return wanted if wanted in self.levels or wanted in self.aggregates else None

    def table(self, name: str) -> int:
        """The number of the paper's per-level table of agent ``name`` (Appendix C's Tables 2 to 7)."""
        return FIRST_LEVEL_TABLE + list(self.levels).index(name)

    @property
    def source(self) -> str:
        """Where the scores come from, for a report: the same words on every install for retrokit's own copy."""
        where = "retrokit's copy" if self.shipped else f"`{self.path}` (${PAPER_ENV})"
        return f"Paper: Nichol et al., *Gotta Learn Fast* (2018), Table 1 and Appendix C, from {where}."


def find_paper_dir() -> Path | None:
    """The folder of ``test-scores.csv``: ``$RETROKIT_PAPER`` when set (``None`` if it has none), else retrokit's."""
    override = os.environ.get(PAPER_ENV)
    if override:
        folder = Path(override).expanduser()
        return folder if (folder / SCORES_FILE).is_file() else None
    return SHIPPED_DIR


def load_paper(folder: Path | None = None) -> PaperScores | None:
    """Read the paper's scores from ``folder`` (default: :func:`find_paper_dir`); ``None`` if absent or unreadable."""
    folder = folder if folder is not None else find_paper_dir()
    if folder is None:
        return None
    path = folder / SCORES_FILE
    scores = PaperScores(path, shipped=folder.resolve() == SHIPPED_DIR)
    try:
        data = read_regular_file(path, "the paper's scores (a CSV file)", MAX_SCORES_BYTES)
        for row in csv.DictReader(data.decode("utf-8").splitlines()):
            entry = PaperEntry(_number(row["score"]), _number(row["score_sd"] or "0"),
                               _optional(row["final_score"]), _optional(row["final_score_sd"]))
            agent, game, state = row["agent"], row["game"], row["state"]
            if state == "Aggregate":
                scores.aggregates[agent] = entry
            else:
                scores.levels.setdefault(agent, {})[f"{game}/{state}"] = entry
    except (RetrokitError, KeyError, ValueError, TypeError, csv.Error):
        return None
    return scores


def _number(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"not a finite number: {text!r}")
    return value


def _optional(text: str | None) -> float | None:
    return _number(text) if text else None
