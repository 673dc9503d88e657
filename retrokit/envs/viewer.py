"""A window that shows frames, for ``render_mode="human"``.

It uses pygame, which retrokit does not require: install it where a display
exists (``pip install 'retrokit-rl[human]'``).
"""

from __future__ import annotations

import numpy as np

from retrokit.errors import EnvError, install_extra


class Viewer:
    """Shows RGB frames in a window, scaled up twice, at most ``fps`` a second.

    Raises:
        EnvError: pygame is not installed or no display can be opened.
    """

    def __init__(self, title: str, fps: int, scale: int = 2) -> None:
        try:
            import pygame
        except ImportError:
            raise EnvError(
                "Expected pygame for render_mode='human', but it is not installed. "
                f"Install it ({install_extra('human')}), or use render_mode='rgb_array'."
            ) from None
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
