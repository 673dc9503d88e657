"""Probe verdicts, and the one rule of which are kept in the data folder.

A probe runs something risky (a core library, a save state) in a child and
reports how it ended. What it found about the thing itself (a crash, an
error) is kept as a record under ``<data>/<kind>/<key>`` so the next process
need not probe again; what it found about the moment (a child that missed
its deadline on a loaded machine, one that could not start) is not: it is
probed again next time. The core probe (:mod:`retrokit.host.corecheck`) and
the state probe (:mod:`retrokit.data.probe`) both keep and read their
verdicts here, through :func:`retrokit.paths.records_dir` (never a link).
"""

from __future__ import annotations

from dataclasses import dataclass

from retrokit import paths
from retrokit.errors import RetrokitError

_SAFE = "safe"
_LIMIT = 4096
"""The most bytes a verdict file may hold: a reason is one line."""


@dataclass(frozen=True)
class ProbeVerdict:
    """What a probe found.

    Attributes:
        safe: The child ran what it was given to the end (or refused it with retrokit's own error).
        reason: Why it is not safe (empty when it is): the signal, a hang, or the child's error.
        lasting: Whether the verdict says something about what was probed (kept), or about this moment (a hang
            on a loaded machine, a child that could not start: probed again next time).
    """

    safe: bool
    reason: str = ""
    lasting: bool = True


def kept_verdict(kind: str, key: str, what: str) -> ProbeVerdict | None:
    """The verdict kept under ``<data>/<kind>/<key>``, or ``None`` (none, unreadable, or through a link).

    Args:
        kind: The records folder (``state-probes``, ``core-probes``).
        key: The record's name (a digest).
        what: What the record is, for errors never shown (``"a probe's verdict"``).
    """
    try:
        text = paths.read_regular_file(paths.records_dir(kind) / key, what, _LIMIT, follow=False).decode("utf-8")
    except (RetrokitError, UnicodeDecodeError):  # only a probe can tell
        return None
    return ProbeVerdict(True) if text == _SAFE else ProbeVerdict(False, text)


def keep_verdict(kind: str, key: str, verdict: ProbeVerdict) -> None:
    """Keep ``verdict`` under ``<data>/<kind>/<key>`` if it is lasting; a temporary one is dropped.

    An unwritable data folder (or a link planted in it) only means probing again next time.
    """
    if not verdict.lasting:
        return
    try:
        text = (_SAFE if verdict.safe else verdict.reason).encode()
        paths.atomic_write(paths.records_dir(kind) / key, text, overwrite=True)
    except RetrokitError:
        pass
