"""What a session pushes to each connected page: the newest screen, and the newest message of each type.

The session offers from its emulator thread; the page's WebSocket sender
(:mod:`retrokit.studio.app`) awaits on the event loop and takes what is there,
so a slow page skips screens instead of queueing them.
"""

from __future__ import annotations

import asyncio
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass
class Screen:
    """One screen to send: its frame number and its RGB pixels, ``(height, width, 3)`` uint8."""

    frame: int
    pixels: np.ndarray



class Subscriber:
    """What a session pushes to one WebSocket: the newest screen and the newest message of each type.

    The session calls :meth:`offer_screen` and :meth:`offer_message` from its thread; the socket's
    sender awaits :meth:`wait` on the event loop and takes what is there.
    """

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self.loop = loop
        self.screen: Screen | None = None
        self.messages: dict[str, dict[str, Any]] = {}
        self._ready = asyncio.Event()

    def offer_screen(self, screen: Screen) -> None:
        """Make ``screen`` the next one to send (called from any thread)."""
        self.screen = screen
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

