"""Running many emulators' frames in one call, on native threads.

A vector env steps all its emulators at once: one call releases the GIL
once, and the calling thread with ``threads`` native workers takes the
emulators one at a time, each running its frames and converting its screen
into the caller's buffer. More emulators than threads share them.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from retrokit.errors import InvalidArgumentError
from retrokit.host import primitives
from retrokit.host.emulator import Emulator


class Runner:
    """Runs a fixed set of emulators' frames together.

    Args:
        emulators: The emulators it runs; a call may run any subset of them.
        threads: Native worker threads besides the calling one (0 runs
            everything on the calling thread).
    """

    def __init__(self, emulators: Sequence[Emulator], threads: int) -> None:
        if threads < 0:
            raise InvalidArgumentError(f"Expected 0 or more worker threads, got {threads}.")
        self._handles = [e.handle for e in emulators]
        self._native = primitives.NativeRunner(threads)

    @property
    def moved(self) -> int:
        """How many times a caller, left waiting, moved a worker that had lost its CPU onto its own.

        Workers are kept off the caller's CPU; when another process takes a
        worker's CPU in the middle of a step, the waiting caller hands it its
        own instead of idling (see ``native/runner.c``).
        """
        return self._native.moved

    def run(
        self,
        which: Sequence[int],
        actions: np.ndarray,
        frames: int,
        screens: Sequence[np.ndarray] | None = None,
        after: int = 0,
    ) -> tuple[bool, ...]:
        """Run some of the emulators for ``frames`` frames, the GIL released.

        Args:
            which: Indices (into the constructor's list) of the emulators to run.
            actions: A uint16 array with one row of port masks per emulator run.
            frames: Frames each runs.
            screens: One ``(H, W, 3)`` buffer per emulator run, to convert its
                last frame into, or ``None``.
            after: Frames of the same step that later calls will run (see :meth:`Emulator.run`).

        Returns:
            Per emulator run, whether its screen was converted (it fitted).
        """
        if not which:
            return ()
        handles = self._handles
        return self._native.run([handles[i] for i in which], actions, frames, screens, after)
