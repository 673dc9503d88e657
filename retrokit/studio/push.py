"""What a session pushes to each connected page: the newest screen, and the newest message of each type.

The session offers from its emulator thread; the page's WebSocket sender
(:mod:`retrokit.studio.app`) awaits on the event loop and takes what is there,
so a slow page skips screens and messages instead of queueing them.

A page that says how many messages it has handled (``{"type": "ack",
"received": N}`` after each, as the studio's page does) is sent at most
:data:`WINDOW` messages ahead of it. Without that, the operating system's and
the browser's buffers between them hold many megabytes: a page slower than
the game (a long candidates list to show, a loaded machine) fell seconds
behind the server, and a Pause waited behind the backlog. Such a page says so
when it connects (``/ws?ack=1``), so the window holds from the first message:
known only from its first ack, a loaded machine sent a new page a backlog of
screens before that ack came in (a second of play behind, 1 run in 8 of the
studio's tests under load).
"""

from __future__ import annotations

import asyncio
from dataclasses import dataclass
from typing import Any

import numpy as np

from retrokit.errors import InvalidArgumentError, shown

WINDOW = 3
"""The most messages (screens and JSON) sent to a page that acknowledges them and not yet handled there."""


@dataclass
class Screen:
    """One screen to send: its frame number and its RGB pixels, ``(height, width, 3)`` uint8."""

    frame: int
    pixels: np.ndarray



def acknowledges(value: str | None) -> bool:
    """Whether a page's ``ack`` query parameter says it acknowledges each message (``1``; ``0`` or none: no).

    Raises:
        InvalidArgumentError: Another value.
    """
    if value not in (None, "0", "1"):
        raise InvalidArgumentError(
            f"Expected ack=1 (the page acknowledges each message) or ack=0 in the socket's URL; got ack={shown(value)}."
        )
    return value == "1"


class Subscriber:
    """What a session pushes to one WebSocket: the newest screen and the newest message of each type.

    The session calls :meth:`offer_screen` and :meth:`offer_message` from its thread; the socket's
    sender awaits :meth:`wait` on the event loop and takes what is there.
    """

    def __init__(self, loop: asyncio.AbstractEventLoop, *, acknowledges: bool = False) -> None:
        self.loop = loop
        self.screen: Screen | None = None
        self.messages: dict[str, dict[str, Any]] = {}
        self.sent = 0  # messages sent on the socket, screens included
        self.screens = 0  # screens offered (see _offer_screen in retrokit.studio.session)
        self.acked: int | None = 0 if acknowledges else None  # how many the page handled; None: it does not say
        self._ready = asyncio.Event()

    def ack(self, received: object) -> None:
        """Note that the page has handled ``received`` messages (on the event loop's thread).

        Raises:
            InvalidArgumentError: ``received`` is not a whole number from 0 to the messages sent.
        """
        if isinstance(received, bool) or not isinstance(received, int) or not 0 <= received <= self.sent:
            raise InvalidArgumentError(
                f"Expected 'received' to be how many messages the page handled, 0 to {self.sent}; got {shown(received)}."
            )
        self.acked = max(self.acked or 0, received)
        self._ready.set()

    def may_send(self) -> bool:
        """Whether another message may go now: always, to a page that does not acknowledge; else within the window."""
        return self.acked is None or self.sent - self.acked < WINDOW

    def offer_screen(self, screen: Screen) -> None:
        """Make ``screen`` the next one to send (called from any thread)."""
        self.screen = screen
        self.screens += 1
        self._wake_soon()

    def offer_message(self, message: dict[str, Any]) -> None:
        """Queue ``message``, replacing an unsent one of its type (called from any thread)."""
        self.messages[str(message.get("type"))] = message
        self._wake_soon()

    def _wake_soon(self) -> None:
        try:
            self.loop.call_soon_threadsafe(self._ready.set)
        except RuntimeError:  # its event loop is closed: the page is gone, and unsubscribing
            pass

    def wake(self) -> None:
        """Make :meth:`wait` return (on the event loop's thread)."""
        self._ready.set()

    async def wait(self) -> None:
        """Wait until something is offered."""
        await self._ready.wait()
        self._ready.clear()

