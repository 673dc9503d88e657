"""stable-retro's ``Movie``: a ``.bk2`` movie read a frame at a time, or recorded a key at a time.

Reading is :func:`retrokit.movie.read_bk2` and writing is
:class:`retrokit.movie.MovieRecorder` (atomic, flushed while it records), so a movie here is
one that retrokit's own tools and stable-retro both play. stable-retro writes over a file at a
movie's path; this writes over one only if this process recorded it (a movie recorded again
under the same name, as ``brute.py``'s ``best.bk2``), and refuses any other file.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from retrokit.data.games import find_game, stable_retro_name
from retrokit.errors import MovieError
from retrokit.movie.bk2 import read_bk2
from retrokit.movie.recorder import MovieRecorder

__all__ = ["Movie", "open_recorder"]

_recorded: set[Path] = set()  # the movies this process recorded here, which recording again may replace


def open_recorder(path: str | os.PathLike[str], game: str, players: int, state: bytes | None) -> MovieRecorder:
    """A recorder writing ``path``, replacing a movie this process recorded there, never another file.

    Raises:
        GameNotFoundError: No such game.
        FileConflictError: Another file is at ``path`` (delete it or pick another name).
    """
    found = find_game(game)
    where = Path(path).resolve()
    recorder = MovieRecorder(where, found.name, found.system.name, players, state, overwrite=where in _recorded)
    _recorded.add(where)
    return recorder


class Movie:
    """A ``.bk2`` movie, as stable-retro's ``retro.Movie(path, record=False, players=1)``.

    Read (``record=False``): :meth:`step` moves to the next frame and says whether there was one;
    :meth:`get_key` tells whether a button is pressed in it. Recorded (``record=True``):
    :meth:`configure` names the game, :meth:`set_state` the start state, :meth:`set_key` presses
    buttons and :meth:`step` appends a frame; :meth:`close` writes the movie.

    Args:
        path: The ``.bk2`` file.
        record: Record a new movie instead of reading one.
        players: How many players a recorded movie holds.

    Raises:
        MovieError: Reading, the file is no movie (the message says what is wrong).
    """

    def __init__(self, path: str | os.PathLike[str], record: bool = False, players: int = 1) -> None:
        self._path, self._record = Path(path), bool(record)
        self._frame = -1
        if self._record:
            self.players = int(players)
            self._game: str | None = None
            self._state: bytes | None = None
            self._keys = [0] * self.players
            self._recorder: MovieRecorder | None = None
        else:
            self._movie = read_bk2(path)
            self.players = self._movie.players

    # --- reading -----------------------------------------------------------------------------

    def step(self) -> bool:
        """Reading, move to the next frame and return whether there is one; recording, append the keys as a frame."""
        if self._record:
            self._recorder_now().record(tuple(self._keys))
            return True
        self._frame += 1
        return self._frame < len(self._movie.frames)

    def get_key(self, key: int, player: int = 0) -> bool:
        """Whether the button of RetroPad id ``key`` (``env.buttons[key]``) is pressed in this frame by ``player``."""
        if self._record:
            return bool(self._keys[player] >> key & 1)
        frames = self._movie.frames
        if not 0 <= self._frame < len(frames):
            return False
        return bool(frames[self._frame][player] >> key & 1)

    def get_game(self) -> str:
        """The game's name, as stable-retro names it (``Airstriker-Genesis-v0``)."""
        game = self._movie.game if not self._record else self._game
        return stable_retro_name(game) if game else ""

    def get_state(self) -> bytes:
        """The start state (uncompressed bytes; empty for a movie from power-on). Loading it checks it."""
        state = self._movie.state if not self._record else self._state
        return bytes(state or b"")

    # --- recording ---------------------------------------------------------------------------

    def configure(self, game: str, emulator: Any = None) -> None:
        """Name the recorded movie's game (the emulator is not needed: the game says its system)."""
        self._require_recording("configure")
        self._game = game

    def set_state(self, state: bytes) -> None:
        """Set the recorded movie's start state (before its first :meth:`step`)."""
        self._require_recording("set_state")
        if self._recorder is not None:
            raise MovieError(f"{self._path}: expected set_state() before the first step(); found frames recorded.")
        self._state = bytes(state)

    def set_key(self, key: int, value: Any, player: int = 0) -> None:
        """Press (``value`` true) or release the button of RetroPad id ``key`` for ``player`` in the next frame."""
        self._require_recording("set_key")
        if not 0 <= key < 16 or not 0 <= player < self.players:
            raise MovieError(
                f"{self._path}: expected a key from 0 to 15 and a player from 0 to {self.players - 1}; "
                f"found key {key}, player {player}."
            )
        bit = 1 << key
        self._keys[player] = self._keys[player] | bit if value else self._keys[player] & ~bit

    def close(self) -> None:
        """Write a recorded movie (reading, nothing to do)."""
        if self._record and (self._recorder is not None or self._game is not None):
            self._recorder_now().close()

    def _recorder_now(self) -> MovieRecorder:
        if self._recorder is None:
            if self._game is None:
                raise MovieError(f"{self._path}: expected configure(game, emulator) before recording frames.")
            self._recorder = open_recorder(self._path, self._game, self.players, self._state)
        return self._recorder

    def _require_recording(self, call: str) -> None:
        if not self._record:
            raise MovieError(f"{self._path}: {call}() records; open the movie with Movie(path, True) to record one.")
