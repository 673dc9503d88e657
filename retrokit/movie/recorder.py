"""Recording an episode's buttons into a ``.bk2`` movie, one frame at a time."""

from __future__ import annotations

import dataclasses
import os
import sys
import threading
import weakref
from collections.abc import Sequence
from pathlib import Path
from typing import Self

from retrokit.data.games import cached_rom_sha1, find_game
from retrokit.data.states import StateRecord
from retrokit.errors import FileConflictError, MovieError, RetrokitError
from retrokit.host.systems import get_system
from retrokit.movie.bk2 import encode_bk2, write_bk2
from retrokit.movie.model import STATE_DIGEST, Movie, layout
from retrokit.paths import atomic_write, ensure_folder

_claims: dict[tuple[Path, str], int] = {}
_claims_lock = threading.Lock()


def record_numbered(
    folder: str | os.PathLike[str], stem: str, game: str, system: str, players: int = 1,
    start_state: bytes | None = None,
) -> MovieRecorder:
    """Start recording into the first free ``<stem>-NNNNNN.bk2`` in ``folder``; return the recorder.

    The name is taken by the movie itself: its header and start state are
    written to a temporary file that is linked into place only if no file has
    that name (the atomic writer, :func:`retrokit.paths.atomic_write`), so envs
    recording into one folder, in this process or in others, each get names of
    their own, none writes over another's file, and a process killed at any
    moment leaves either no movie or one that plays (a name reserved by an empty
    file first left an empty ``.bk2`` to a kill in the few milliseconds before the
    movie was written).

    Raises:
        FileSystemError: The folder cannot be written.
    """
    folder = Path(folder).resolve()
    with _claims_lock:
        n = _claims.get((folder, stem), 0)
        while True:
            path = folder / f"{stem}-{n:06d}.bk2"
            n += 1
            if os.path.lexists(path):
                continue
            try:
                recorder = MovieRecorder(path, game, system, players, start_state)
            except FileConflictError:  # another process took the name meanwhile
                continue
            _claims[folder, stem] = n
            return recorder


def state_header(game: str, state: bytes) -> dict[str, str]:
    """The header lines that record what a movie's start state is for, as retrokit's states do.

    ``SHA1`` is the ROM's SHA-1 (the key's meaning in BizHawk, whose format
    ``.bk2`` is; stable-retro writes ``?`` and reads it never), and
    ``StateSHA256`` the start state's digest, so playback can tell a state for
    another ROM, or one changed since, from the one recorded.
    """
    try:
        found = find_game(game)
        rom = found.rom_path()
    except RetrokitError:
        return {}
    if rom is None:
        return {}
    record = StateRecord.of(found.name, cached_rom_sha1(rom, found.system), state)
    return {"SHA1": record.rom_sha1, STATE_DIGEST: record.sha256}


#: How often, in seconds of wall-clock time, a recording movie is written out whole while it records.
FLUSH_SECONDS = 1.0


class _Flusher:
    """The one thread of a process that writes every recording movie with new frames out, each :data:`FLUSH_SECONDS`.

    A thread, not a check in :meth:`MovieRecorder.record`: a script that steps,
    then thinks, sleeps or waits on a learner for longer, would otherwise keep its
    last steps unwritten until its next one, and a kill then took them. The
    files are held weakly (a dropped recorder's finalizer writes its movie), and
    a forked child starts a thread of its own for its own recorders.
    """

    lock = threading.Lock()
    files: weakref.WeakSet[_MovieFile] = weakref.WeakSet()
    pid: int | None = None  # the process whose thread runs

    @classmethod
    def watch(cls, file: _MovieFile) -> None:
        with cls.lock:
            cls.files.add(file)
            if cls.pid != os.getpid():
                cls.pid = os.getpid()
                threading.Thread(target=cls._run, name="retrokit-movie-flusher", daemon=True).start()

    @classmethod
    def _run(cls) -> None:
        tick = threading.Event()
        while not tick.wait(FLUSH_SECONDS):
            with cls.lock:
                files = list(cls.files)
            for file in files:
                file.flush_pending()


class _MovieFile:
    """Where a recording movie goes, and what was written of it: shared with the recorder's finalizer.

    Kept apart from :class:`MovieRecorder` so that the finalizer which writes
    the movie at exit, or when a recorder is dropped unclosed, holds no
    reference to the recorder itself.
    """

    def __init__(self, path: Path, movie: Movie, overwrite: bool) -> None:
        self.path = path
        self.movie = movie
        self.overwrite = overwrite
        self.written: int | None = None  # frames in the file; None: nothing written yet
        self.pid = os.getpid()  # a forked child must not write its parent's movie
        self.closed = False
        self.error: RetrokitError | OSError | None = None  # what the flusher thread met, for the recorder to raise
        self._lock = threading.Lock()  # one writer at a time: an older snapshot never replaces a newer one

    def write(self, *, last: bool = False) -> None:
        """Write the movie whole, as it is now, replacing what this recorder wrote before (atomically).

        The first write makes a new file or fails (unless asked to overwrite), even where an identical movie is:
        another process starting the same episode made that one, and it is not this recorder's to write on.

        Args:
            last: The recorder is closing: no write follows this one.
        """
        with self._lock:
            if self.closed:
                return
            # The frames so far: the recording thread appends on while this one encodes.
            movie = dataclasses.replace(self.movie, frames=list(self.movie.frames))
            if self.written is None and not self.overwrite:
                atomic_write(self.path, encode_bk2(movie))
            else:
                write_bk2(self.path, movie, overwrite=True)
            self.written = len(movie.frames)
            self.closed = last

    def flush_pending(self) -> None:
        """The flusher thread's call: write the movie if it has frames the file lacks; keep an error for the recorder."""
        if os.getpid() != self.pid or self.closed or len(self.movie.frames) == self.written or self.error:
            return
        try:
            self.write()
        except (RetrokitError, OSError) as exc:
            self.error = exc

    def write_at_exit(self) -> None:
        """The finalizer: complete the movie of a script that exits, or drops its recorder, without close()."""
        if os.getpid() != self.pid:
            return
        try:
            self.write(last=True)
        except (RetrokitError, OSError) as exc:  # at exit there is no caller to raise to: say it once
            print(f"retrokit: the movie {self.path} could not be written at exit: {exc}", file=sys.stderr)


class MovieRecorder:
    """Collects the buttons of every emulated frame, and writes the movie on :meth:`close`.

    Record every frame the console runs, with the buttons that frame really saw
    (after sticky actions), starting from ``start_state``; then the movie replays
    exactly. stable-retro's own recordings begin with the frame its ``reset``
    runs with no buttons pressed.

    Nothing recorded is lost to a process that ends badly: the movie (its
    header and start state) is written when the recorder is made; while it records,
    a thread writes the movie out whole (atomically, so the file is always a
    playable movie) every :data:`FLUSH_SECONDS` it has new frames, whatever the
    script does meanwhile (steps, sleeps, waits on a learner), so a process
    killed with SIGKILL leaves a movie of all but its last second; and a script
    that exits, or drops the recorder, without :meth:`close` gets its movie
    written whole by a finalizer.

    Args:
        path: The ``.bk2`` file to write.
        game: The game's name, ``<Name>-<System>``.
        system: The system's name.
        players: How many players' buttons each frame holds.
        start_state: The uncompressed state the episode starts from, or ``None``
            for power-on (stable-retro cannot open movies without a state).
        overwrite: Replace a file already at ``path``.

    Raises:
        FileConflictError: A file is already at ``path`` and ``overwrite`` is false.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        game: str,
        system: str,
        players: int = 1,
        start_state: bytes | None = None,
        *,
        overwrite: bool = False,
    ) -> None:
        path = Path(path)
        if not overwrite and path.exists():  # fail before the episode
            raise FileConflictError(
                f"Expected no file at {path} to record a movie into; found one. "
                "Delete it, choose another name, or pass overwrite=True to replace it."
            )
        self.movie = Movie(game, system, players, start_state)
        if start_state is not None:
            self.movie.header.update(state_header(self.movie.game, start_state))
        self._layout = layout(self.movie.system)
        # RetroPad ids among the console's that no button sits on (the NES's 1, under action_type="all") reach
        # no game; stable-retro's recording drops them, and so does this. Bits past the pad are refused.
        system = get_system(self.movie.system)
        self._kept = ~(((1 << len(system.buttons)) - 1) & ~system.present_mask)
        self._players = self.movie.players
        self._file = _MovieFile(path, self.movie, overwrite)
        self._file.write()  # now, whole and atomically: a recorder killed before its first flush leaves a movie that plays
        self._finalizer = weakref.finalize(self, self._file.write_at_exit)
        _Flusher.watch(self._file)
        self._closed = False

    @property
    def path(self) -> Path:
        """The ``.bk2`` file the movie goes to."""
        return self._file.path

    def record(self, masks: Sequence[int]) -> None:
        """Append one frame: one RetroPad bit mask per port.

        Masks beyond the movie's players must be 0 (e.g. an emulator's idle second port). Bits of
        RetroPad ids the console has no button on are dropped, as stable-retro's recording drops them.

        Raises:
            MovieError: The recorder is closed, too few masks are given, a port beyond
                the players presses buttons, or a mask presses a button the format
                cannot hold.
        """
        if self._closed:
            raise MovieError(f"Expected an open recorder; found it closed after writing {self.path}. Make a new one.")
        self._raise_flush_error()
        kept = self._kept
        frame = tuple(int(m) & kept for m in masks[: self._players])
        frames = self.movie.frames
        if len(frame) < self._players or any(int(m) for m in masks[self._players :]):
            raise MovieError(
                f"{self.path} frame {len(frames)}: expected {self._players} mask(s), one per player, then only "
                f"zeros; found {list(masks)!r}."
            )
        if any(m < 0 or m & ~self._layout.allowed for m in frame):
            self._layout.check_frame(frame, self._players, f"{self.path} frame {len(frames)}")  # raises, naming it
        frames.append(frame)

    def flush(self) -> None:
        """Write the movie recorded so far now (a playable movie, replaced atomically by later writes and by close).

        Raises:
            FileConflictError: A different file appeared at the path meanwhile.
        """
        self._raise_flush_error()
        if not self._closed and len(self.movie.frames) != self._file.written:
            self._file.write()

    def _raise_flush_error(self) -> None:
        """Raise, in the recording thread, what the flusher thread met writing the movie (once)."""
        error, self._file.error = self._file.error, None
        if isinstance(error, RetrokitError):
            raise error
        if error is not None:
            raise MovieError(f"Expected to write the movie {self.path} as it records; it failed: {error}.")

    def __len__(self) -> int:
        """How many frames have been recorded."""
        return len(self.movie.frames)

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` has written the movie."""
        return self._closed

    def close(self) -> Path:
        """Write the movie (once; later calls do nothing) and return its path.

        Raises:
            FileConflictError: A different file appeared at the path meanwhile.
        """
        if not self._closed:
            self._file.write(last=True)  # the whole movie: whatever the flusher thread met before is moot
            self._finalizer.detach()
            self._closed = True
        return self.path

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class EpisodeMovies:
    """Records each episode of an env into a movie of its own: an observer of the env's stepper.

    Every episode gets the first free ``<stem>-NNNNNN.bk2`` in ``folder``
    (:func:`record_numbered`), so a file already there is never replaced.

    Args:
        folder: Where the movies go (made if missing).
        stem: The movies' name before the number, e.g. ``Dasher-Genesis-Zone1.Act1``.
        game: The game's name.
        system: The system's name.
        players: Players whose buttons each frame holds.
        start_state: The state every episode starts from, or ``None`` for power-on.
    """

    def __init__(
        self,
        folder: str | os.PathLike[str],
        stem: str,
        game: str,
        system: str,
        players: int,
        start_state: bytes | None,
    ) -> None:
        self.folder, self.stem = Path(folder), stem
        self._movie = (game, system, players, start_state)
        self.recorder: MovieRecorder | None = None

    def start(self) -> None:
        """Begin an episode's movie, ending the last one if it is still open."""
        self.end()
        ensure_folder(self.folder, "to record movies into")
        self.recorder = record_numbered(self.folder, self.stem, *self._movie)

    def frames(self, first: tuple[int, ...], applied: tuple[int, ...], count: int) -> None:
        """Record ``count`` frames: the first held ``first``, the rest ``applied``."""
        recorder = self.recorder
        if recorder is None:  # frames before the first reset() belong to no episode
            return
        recorder.record(first)
        for _ in range(count - 1):
            recorder.record(applied)

    def end(self) -> Path | None:
        """Write the episode's movie, if one is open; return its path."""
        recorder, self.recorder = self.recorder, None
        if recorder is None:
            return None
        return recorder.close()  # its file, written when it began: no one else's is at that name
