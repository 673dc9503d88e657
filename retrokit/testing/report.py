"""The results of checking a game: one :class:`Result` per check, a :class:`GameReport` per game.

A check ends in one of four statuses: ``pass``, ``warn`` (worth a look, not a
failure), ``fail``, or ``skip`` (could not be run; the message says why, e.g.
no ROM). A report passes when none of its results failed.
"""

from __future__ import annotations

import json
import os
import shutil
import textwrap
from collections import Counter
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass, field

from retrokit.paths import atomic_write

__all__ = ["FAIL", "PASS", "SKIP", "STATUSES", "WARN", "GameReport", "Result", "render", "summary", "write_json"]

PASS, WARN, FAIL, SKIP = "pass", "warn", "fail", "skip"
STATUSES = (PASS, WARN, FAIL, SKIP)


@dataclass(frozen=True)
class Result:
    """The outcome of one check.

    Attributes:
        check: What was checked, e.g. ``"schema"``, ``"state loads"``, ``"smoke run"``.
        status: ``"pass"``, ``"warn"``, ``"fail"`` or ``"skip"``.
        message: What was found (for a failure: what was expected, what was found, how to fix it).
        state: The state the check ran on, or ``""``.
        scenario: The scenario the check ran on, or ``""``.
    """

    check: str
    status: str
    message: str = ""
    state: str = ""
    scenario: str = ""

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"Expected a status among {STATUSES}, got {self.status!r}.")


@dataclass
class GameReport:
    """Every result of checking one game.

    Attributes:
        game: The game's name.
        results: The results, in the order the checks ran.
    """

    game: str
    results: list[Result] = field(default_factory=list)

    def add(self, check: str, status: str, message: str = "", *, state: str = "", scenario: str = "") -> Result:
        """Record a result and return it."""
        result = Result(check, status, message, state, scenario)
        self.results.append(result)
        return result

    def extend(self, results: Iterable[Result]) -> None:
        """Record several results."""
        self.results.extend(results)

    @property
    def passed(self) -> bool:
        """Whether no check failed."""
        return not self.failures

    @property
    def failures(self) -> list[Result]:
        """The failed results."""
        return [r for r in self.results if r.status == FAIL]

    def counts(self) -> Counter[str]:
        """How many results have each status."""
        return Counter(r.status for r in self.results)

    def find(self, check: str, *, state: str | None = None, status: str | None = None) -> list[Result]:
        """The results of one check, optionally only on one state or with one status."""
        return [
            r for r in self.results
            if r.check == check and (state is None or r.state == state) and (status is None or r.status == status)
        ]

    def to_dict(self) -> dict:
        """The report as plain data (for JSON)."""
        return {"game": self.game, "passed": self.passed, "counts": dict(self.counts()),
                "results": [asdict(r) for r in self.results]}


def render(report: GameReport, *, width: int | None = None) -> str:
    """Return the report as a text table: check, state (and scenario), result, message."""
    width = width or shutil.get_terminal_size((120, 24)).columns
    rows = [(r.check, " ".join(filter(None, (r.state, f"[{r.scenario}]" if r.scenario else ""))), r.status.upper(),
             r.message)
            for r in report.results]
    heads = ("check", "state", "result", "message")
    widths = [max([len(h), *(len(row[i]) for row in rows)]) for i, h in enumerate(heads[:3])]
    widths[1] = min(widths[1], 40)
    indent = sum(widths) + 6
    room = max(30, width - indent)
    lines = [f"{report.game}", "  ".join(h.ljust(w) for h, w in zip(heads[:3], widths)) + "  message",
             "  ".join("-" * w for w in widths) + "  " + "-" * min(room, 40)]
    for row in rows:
        # A message's first line is wrapped; later ones (a scenario's source line and its caret) keep their shape.
        first, *rest = row[3].split("\n") or [""]
        message = (textwrap.wrap(first, room) or [""]) + [line.rstrip() for line in rest]
        lines.append("  ".join(c.ljust(w) for c, w in zip(row[:3], widths)) + "  " + message[0])
        lines.extend(" " * indent + more for more in message[1:])
    return "\n".join(lines)


def summary(reports: Sequence[GameReport]) -> str:
    """One line: games passed and failed, and the number of checks by status."""
    total: Counter[str] = Counter()
    for report in reports:
        total.update(report.counts())
    failed = [r.game for r in reports if not r.passed]
    games = f"{len(reports) - len(failed)} of {len(reports)} game{'s' * (len(reports) != 1)} passed"
    words = {PASS: "passed", WARN: "warnings", FAIL: "failed", SKIP: "skipped"}
    checks = ", ".join(f"{total[s]} {words[s]}" for s in STATUSES)
    return f"{games} ({checks})" + (f"; failed: {', '.join(failed)}" if failed else "")


def write_json(path: str | os.PathLike[str], reports: Sequence[GameReport]) -> None:
    """Write every result of every report to a JSON file (replacing it)."""
    doc = {"passed": all(r.passed for r in reports), "games": [r.to_dict() for r in reports]}
    atomic_write(path, (json.dumps(doc, indent=2) + "\n").encode(), overwrite=True)
