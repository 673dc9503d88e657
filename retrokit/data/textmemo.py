"""Answers computed from a data file's text, kept by the text's SHA-256 so that reading the file again is cheap.

Every ``make()`` reads its ``game.yaml`` and scenario again, so that an edit
shows at once; parsing and schema-checking the same text again was over half
of a warm ``make()``'s CPU. What those steps answer depends only on the text
(and a few names passed with it), so a :class:`TextMemo` keeps each answer
under the text's digest, never the text itself, and only for texts under
:data:`MAX_TEXT_CHARS`: a shipped data file is a few kilobytes, while a
4 MiB hostile one could parse into hundreds of megabytes. A call that raises
keeps nothing, so an error is found and raised afresh each time.
"""

from __future__ import annotations

import hashlib
import threading
from collections.abc import Callable, Hashable
from typing import Generic, TypeVar

T = TypeVar("T")

MAX_TEXT_CHARS = 256 * 1024
"""The longest text whose answer is kept (longer ones are computed every time)."""


class TextMemo(Generic[T]):
    """Up to ``size`` answers, by (the text's SHA-256, ``extra``), the oldest dropped first; safe across threads.

    Args:
        size: How many answers to keep.
    """

    def __init__(self, size: int = 256) -> None:
        self._size = size
        self._answers: dict[tuple[bytes, Hashable], T] = {}
        self._lock = threading.Lock()

    def get(self, text: str, extra: Hashable, compute: Callable[[], T]) -> T:
        """``compute()``'s answer for ``text`` (and ``extra``): kept from an earlier call, else computed now.

        The answer is shared by every caller of the same text: return only values nobody mutates (copy a
        mutable one on the way out).
        """
        if len(text) > MAX_TEXT_CHARS:
            return compute()
        key = (hashlib.sha256(text.encode("utf-8", "surrogatepass")).digest(), extra)
        with self._lock:
            if key in self._answers:
                return self._answers[key]
        answer = compute()
        with self._lock:
            if len(self._answers) >= self._size:
                del self._answers[next(iter(self._answers))]  # the oldest
            self._answers[key] = answer
        return answer
