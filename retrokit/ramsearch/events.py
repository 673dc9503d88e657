"""Suggestions for a done condition: the bytes that change at the moments the user marks.

A value search finds what a HUD shows, but an episode should end on the
event itself: the frame the player dies, not the life taken away seconds
later; the frame the level is cleared. Play a script (or a movie) from the
game now, mark the frames where the event happens (``--at 133 --at 331``:
frame numbers of that play, from 1), and :func:`suggest_done` ranks every byte
of RAM by how well its changes line up with them: a change within ``window``
frames of every mark first, then the fewest changes anywhere else. Each is
given with its value before and after each mark and a condition a scenario's
``done`` could use once it is saved as a field.

The RAM is compared frame by frame as the play runs, so nothing is kept per
frame: a play of :data:`MAX_FRAMES` frames costs one pass over the RAM a frame.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from retrokit.errors import InvalidArgumentError, shown

MAX_FRAMES = 36_000  # ten minutes of play: a death or a level's end is reached sooner
MAX_EVENTS = 16
MAX_WINDOW = 60


@dataclass(frozen=True)
class Suggestion:
    """One byte, and how its changes line up with the marks.

    Attributes:
        address: Its console address.
        hits: At how many marks it changed (within the window).
        others: At how many other frames it changed.
        moments: For each mark: ``(frame, value before, value after)`` around its window.
        condition: A done condition over a field ``NAME`` at this byte that holds at the marks.
    """

    address: int
    hits: int
    others: int
    moments: tuple[tuple[int, int, int], ...]
    condition: str


def check_marks(marks: Sequence[int], window: int) -> list[int]:
    """The marked frames, sorted; checked to be 1 or more and farther apart than two windows.

    Raises:
        InvalidArgumentError: None, too many, a frame below 1, a window out of range, or two marks too close.
    """
    if not isinstance(window, int) or isinstance(window, bool) or not 0 <= window <= MAX_WINDOW:
        raise InvalidArgumentError(f"Expected a window of 0 to {MAX_WINDOW} frames; got {shown(window)}.")
    frames = sorted(marks)
    if not 1 <= len(frames) <= MAX_EVENTS or any(not isinstance(f, int) or isinstance(f, bool) or f < 1 for f in frames):
        raise InvalidArgumentError(
            f"Expected 1 to {MAX_EVENTS} marked frames, each 1 or more (frames of the play, counted from 1); "
            f"got {shown(list(marks))}."
        )
    for a, b in itertools.pairwise(frames):
        if b - a <= 2 * window:
            raise InvalidArgumentError(
                f"Expected marks more than {2 * window} frames apart (two windows of {window}); got {a} and {b}. "
                "Mark each event once, or pass a smaller --window."
            )
    return frames


def suggest_done(
    ram: Iterator[np.ndarray],
    marks: Sequence[int],
    *,
    window: int = 2,
    limit: int = 10,
    address_of: Callable[[int], int] = int,
) -> tuple[list[Suggestion], int]:
    """Rank the bytes of RAM by how well their changes line up with the marked frames.

    Args:
        ram: The RAM (console-order bytes) at the start, then after each frame played (frame 1, 2, ...), each a
            new array (some are kept as they are).
        marks: The frames of the event, counted from 1.
        window: How many frames before and after a mark a change still counts as at it.
        limit: How many suggestions to return.
        address_of: The console address of a position in the RAM's bytes (by default the position itself).

    Returns:
        The best ``limit`` bytes (every byte that changed at a mark at least once, best first), and how many
        frames were played.

    Raises:
        InvalidArgumentError: The marks are malformed, or beyond the frames played.
    """
    frames = check_marks(marks, window)
    start = next(ram)
    previous = start
    size = len(start)
    hits = np.zeros((len(frames), size), dtype=bool)
    others = np.zeros(size, dtype=np.int64)
    before = [start if frame - window <= 1 else None for frame in frames]
    after: list[np.ndarray | None] = [None] * len(frames)
    played = 0
    for played, now in enumerate(ram, 1):
        if played > MAX_FRAMES:
            raise InvalidArgumentError(f"Expected a play of at most {MAX_FRAMES:,} frames to mark; got a longer one.")
        changed = now != previous
        event = next((k for k, f in enumerate(frames) if abs(played - f) <= window), None)
        if event is None:
            others += changed
        else:
            hits[event] |= changed
        for k, frame in enumerate(frames):  # each frame's RAM is a new array: kept as it is, never copied
            if played == frame - window - 1:
                before[k] = now
            if played == frame + window:
                after[k] = now
        previous = now
    if frames[-1] > played:
        raise InvalidArgumentError(
            f"Expected marks within the {played:,} frames played; got {frames[-1]:,}. Mark a frame of the play."
        )
    for k in range(len(frames)):  # a window running past the play's end ends with it
        after[k] = previous if after[k] is None else after[k]
    count = hits.sum(axis=0)
    chosen = np.flatnonzero(count)
    order = np.lexsort((chosen, others[chosen], -count[chosen]))[:limit]
    return [_suggestion(int(p), address_of(int(p)), frames, hits, others, before, after) for p in chosen[order]], played


def _suggestion(position: int, address: int, frames: list[int], hits, others, before, after) -> Suggestion:
    moments = tuple((f, int(before[k][position]), int(after[k][position])) for k, f in enumerate(frames) if hits[k, position])
    olds, news = {m[1] for m in moments}, {m[2] for m in moments}
    if len(news) == 1 and not olds & news:
        condition = f"NAME == {next(iter(news))}"
    elif all(new > old for _, old, new in moments):
        condition = "NAME > prev(NAME)"
    elif all(new < old for _, old, new in moments):
        condition = "NAME < prev(NAME)"
    else:
        condition = "NAME != prev(NAME)"
    return Suggestion(address, int(hits[:, position].sum()), int(others[position]), moments, condition)
