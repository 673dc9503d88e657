"""Playing a game by hand in a window, to save states and record movies (``retrokit play``).

Keys (also listed in ``docs/integrate.md``):

- arrows: the D-pad; ``Z`` ``X`` ``C``: A B C (Genesis), or the system's
  buttons in RetroPad order; ``Enter``: START; ``Tab``: SELECT / MODE;
  ``A`` ``S`` ``D``: X Y Z (or L R).
- ``F5``: save the current state as ``<name>.state`` (``<name>.2.state``,
  ... when taken) in the output folder;
- ``F9``: start recording a movie, from the current state; ``F9`` again
  writes it as ``movies/<name>.bk2`` (next free name) in the output folder;
- ``Escape`` or closing the window: quit (a movie being recorded is written).

Held keys are tracked from key events, so scripted events (a test posting
them under SDL's dummy video driver) play exactly like a keyboard.
"""

from __future__ import annotations

from pathlib import Path

from retrokit.data.games import Game
from retrokit.data.names import check_state_name
from retrokit.data.statecheck import load_state, remember_written
from retrokit.data.states import write_state
from retrokit.errors import EnvError, install_extra
from retrokit.host.emulator import Emulator
from retrokit.movie.recorder import MovieRecorder, record_numbered

__all__ = ["KEYS", "PlaySession"]

#: pygame key name -> RetroPad id (0 B, 1 Y, 2 SELECT, 3 START, 4-7 D-pad, 8 A, 9 X, 10 L, 11 R).
KEYS = {
    "up": 4, "down": 5, "left": 6, "right": 7,
    "return": 3, "tab": 2,
    "z": 1, "x": 0, "c": 8,  # Genesis: A, B, C (the core maps RetroPad Y, B, A to them)
    "a": 10, "s": 9, "d": 11,  # Genesis: X, Y, Z
}
SAVE_KEY, MOVIE_KEY, QUIT_KEY = "f5", "f9", "escape"


class PlaySession:
    """A game in a window, played from the keyboard, saving states and movies on keys.

    Args:
        game: The game.
        state: The state to start from (``None``: the default state, or power-on if none).
        folder: Where saved states (and ``movies/``) go.
        name: The name of saved states and movies.
        scale: Window pixels per console pixel.

    Raises:
        EnvError: pygame is missing or no display can be opened.
    """

    def __init__(self, game: Game, state: str | None, folder: Path, *, name: str = "Play", scale: int = 2) -> None:
        check_state_name(name, what="name of saved states")  # F5 writes <folder>/<name>.state
        try:
            import pygame
        except ImportError:
            raise EnvError(f"Expected pygame for retrokit play; install it: {install_extra('human')}.") from None
        self._pygame = pygame
        try:
            pygame.display.init()
        except pygame.error as exc:
            raise EnvError(f"Expected a display for retrokit play; found none ({exc}).") from None
        self.game, self.folder, self.name, self.scale = game, Path(folder), name, scale
        self.emulator = Emulator(game.system, game.require_rom())
        start = state or game.default_state
        if start is not None:
            self.emulator.set_state(load_state(game, game.state_path(start)))  # checked: it may be any file
        self.held: set[int] = set()
        self.recorder: MovieRecorder | None = None
        self.saved: list[Path] = []
        self.movies: list[Path] = []
        self.running = True
        self._screen = None
        self._clock = pygame.time.Clock()
        self._codes = {pygame.key.key_code(k): bit for k, bit in KEYS.items()}
        self._special = {pygame.key.key_code(k): k for k in (SAVE_KEY, MOVIE_KEY, QUIT_KEY)}

    def run(self, frames: int | None = None, *, fps: int = 60) -> None:
        """Play until quit (or for ``frames`` frames): handle keys, run a frame, show it."""
        count = 0
        while self.running and (frames is None or count < frames):
            self._handle_events()
            if not self.running:
                break
            mask = 0
            for bit in self.held:
                mask |= 1 << bit
            self.emulator.run([mask, 0], 1)
            if self.recorder is not None:
                self.recorder.record(self.emulator.held()[:1])
            self._show()
            if fps:
                self._clock.tick(fps)
            count += 1

    @property
    def window_size(self) -> tuple[int, int] | None:
        """The window's size in pixels, once a frame was shown."""
        return None if self._screen is None else self._screen.get_size()

    def save_state(self) -> Path:
        """Save the current state as the next free ``<name>[.N].state`` in the folder."""
        path = self.folder / f"{self.name}.state"
        n = 1
        while path.exists():
            n += 1
            path = self.folder / f"{self.name}.{n}.state"
        state = self.emulator.get_state()
        write_state(path, state)
        remember_written(self.game, state)  # this machine wrote it: loading it again needs no probe
        self.saved.append(path)
        print(f"saved {path}")
        return path

    def toggle_movie(self) -> Path | None:
        """Start recording a movie from now, or stop and write the one being recorded (returning its path)."""
        if self.recorder is None:
            (self.folder / "movies").mkdir(parents=True, exist_ok=True)
            self.recorder = record_numbered(
                self.folder / "movies", self.name, self.game.name, self.game.system.name, 1, self.emulator.get_state()
            )
            print(f"recording {self.recorder.path}")
            return None
        path = self.recorder.close()
        self.recorder = None
        self.movies.append(path)
        print(f"wrote {path}")
        return path

    def close(self) -> None:
        """Write a movie being recorded, close the emulator and the window."""
        if self.recorder is not None:
            self.toggle_movie()
        self.emulator.close()
        self._pygame.display.quit()

    def _handle_events(self) -> None:
        pygame = self._pygame
        for event in pygame.event.get():
            if event.type == pygame.QUIT:
                self.running = False
            elif event.type == pygame.KEYDOWN:
                special = self._special.get(event.key)
                if special == QUIT_KEY:
                    self.running = False
                elif special == SAVE_KEY:
                    self.save_state()
                elif special == MOVIE_KEY:
                    self.toggle_movie()
                elif event.key in self._codes:
                    self.held.add(self._codes[event.key])
            elif event.type == pygame.KEYUP and event.key in self._codes:
                self.held.discard(self._codes[event.key])

    def _show(self) -> None:
        import numpy as np

        pygame = self._pygame
        frame = self.emulator.screen()
        height, width = frame.shape[:2]
        size = (width * self.scale, height * self.scale)
        if self._screen is None or self._screen.get_size() != size:
            self._screen = pygame.display.set_mode(size)
            pygame.display.set_caption(f"retrokit play {self.game.name}: F5 save state, F9 movie, Esc quit")
        surface = pygame.surfarray.make_surface(np.ascontiguousarray(frame.swapaxes(0, 1)))
        self._screen.blit(pygame.transform.scale(surface, size), (0, 0))
        pygame.display.flip()
