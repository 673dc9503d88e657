"""A window that shows frames, for ``render_mode="human"``.

It uses pygame, which retrokit does not require: install it where a display
exists (``pip install 'retrokit-rl[human]'``). Whether it is there decides
the envs' ``metadata["render_modes"]`` (:func:`render_modes`), and
:func:`require_human` is the one check that ``render_mode="human"`` can work,
made when the env is made.
"""

from __future__ import annotations

import functools
import importlib.util
import os
import sys

import numpy as np

from retrokit.errors import EnvError, MissingExtraError, install_extra


def human_available() -> bool:
    """Whether pygame can be imported, without importing it (which takes a while and prints a banner)."""
    if "pygame" in sys.modules:  # imported, or blocked with None (as tests do)
        return sys.modules["pygame"] is not None
    return _pygame_found()


@functools.cache  # every make() asks (its render modes), and finding a module walks sys.path: ~1 ms a time
def _pygame_found() -> bool:
    try:
        return importlib.util.find_spec("pygame") is not None
    except (ImportError, ValueError):  # a broken pygame
        return False


def render_modes() -> list[str]:
    """The render modes that can work here: ``"human"`` only where pygame is installed."""
    return ["rgb_array", "human"] if human_available() else ["rgb_array"]


def require_human() -> None:
    """Refuse ``render_mode="human"`` where pygame is missing, before an env is built.

    Raises:
        MissingExtraError: pygame is not installed; the message says how to install it.
    """
    if not human_available():
        raise MissingExtraError(
            f"Expected pygame for render_mode='human', but it is not installed. Install it ({install_extra('human')}), "
            f"or use render_mode='rgb_array'."
        )


#: SDL's hint (read from the environment when SDL starts) not to catch SIGINT and SIGTERM. Caught, each becomes
#: a quit event in SDL's queue, which ends nothing: ``timeout``, ``kill`` and process managers could not stop a
#: program showing a window. Left alone, SIGTERM ends it as it ends any Python program (SIGINT stays Python's).
SDL_SIGNAL_HINT = "SDL_NO_SIGNAL_HANDLERS"


class Viewer:
    """Shows RGB frames in a window, scaled up twice, at most ``fps`` a second.

    SIGTERM ends the program as it ends any Python program (SDL is told not to
    turn it into a quit event), and the window's close button ends it as Ctrl-C
    does: the window closes and :meth:`show` raises ``KeyboardInterrupt``.

    Raises:
        MissingExtraError: pygame is not installed.
        EnvError: No display can be opened.
    """

    def __init__(self, title: str, fps: float, scale: int = 2) -> None:
        require_human()
        os.environ.setdefault(SDL_SIGNAL_HINT, "1")  # before SDL starts: a user's own "0" is kept
        import pygame

        self._pygame = pygame
        self.title, self.fps, self.scale = title, fps, scale
        self._screen = None
        self._open_display()
        self._clock = pygame.time.Clock()

    def _open_display(self) -> None:
        pygame = self._pygame
        try:
            pygame.display.init()
        except pygame.error as exc:
            raise EnvError(f"Expected a display for render_mode='human', found none ({exc}). Use render_mode='rgb_array'.") from None

    def show(self, frame: np.ndarray) -> None:
        """Draw one frame and keep the window responsive.

        Raises:
            KeyboardInterrupt: The window's close button was pressed (the window is closed; showing
                another frame opens it again).
        """
        pygame = self._pygame
        height, width = frame.shape[:2]
        size = (width * self.scale, height * self.scale)
        if self._screen is None or self._screen.get_size() != size:
            self._open_display()  # again, after the close button closed it
            self._screen = pygame.display.set_mode(size)
            pygame.display.set_caption(self.title)
        surface = pygame.surfarray.make_surface(np.ascontiguousarray(frame.swapaxes(0, 1)))
        self._screen.blit(pygame.transform.scale(surface, size), (0, 0))
        # Every event is taken (nobody else reads them here), so none piles up; a quit is the close button.
        if any(event.type == pygame.QUIT for event in pygame.event.get()):
            self.close()
            raise KeyboardInterrupt(f"the {self.title} window was closed")
        pygame.display.flip()
        self._clock.tick(self.fps)

    def close(self) -> None:
        """Close the window."""
        self._screen = None
        self._pygame.display.quit()
