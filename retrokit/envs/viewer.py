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


class Viewer:
    """Shows RGB frames in a window, scaled up twice, at most ``fps`` a second.

    Raises:
        MissingExtraError: pygame is not installed.
        EnvError: No display can be opened.
    """

    def __init__(self, title: str, fps: float, scale: int = 2) -> None:
        require_human()
        import pygame

        self._pygame = pygame
        try:
            pygame.display.init()
        except pygame.error as exc:
            raise EnvError(f"Expected a display for render_mode='human', found none ({exc}). Use render_mode='rgb_array'.") from None
        self.title, self.fps, self.scale = title, fps, scale
        self._screen = None
        self._clock = pygame.time.Clock()

    def show(self, frame: np.ndarray) -> None:
        """Draw one frame and keep the window responsive."""
        pygame = self._pygame
        height, width = frame.shape[:2]
        size = (width * self.scale, height * self.scale)
        if self._screen is None or self._screen.get_size() != size:
            self._screen = pygame.display.set_mode(size)
            pygame.display.set_caption(self.title)
        surface = pygame.surfarray.make_surface(np.ascontiguousarray(frame.swapaxes(0, 1)))
        self._screen.blit(pygame.transform.scale(surface, size), (0, 0))
        pygame.event.pump()
        pygame.display.flip()
        self._clock.tick(self.fps)

    def close(self) -> None:
        """Close the window."""
        self._pygame.display.quit()
