"""``RamSearch``: a RAM search on a running game, in the spirit of BizHawk's and Gym Retro's.

Start from a save state, move the game between snapshots (hold buttons for
some frames, play a script of taps, holds and waits or a ``.bk2`` movie, poke
a value), narrow the candidates with filters, look at them, and write the one
you found into the game's ``game.yaml``. The inputs played since the last
state loaded are kept, so the search can be saved as a movie from that state,
and the state it reached as a state of the game::

    from retrokit.ramsearch import RamSearch

    search = RamSearch("Dasher-Genesis", "Zone1.Act1")
    search.filter("equal", 3)                  # 3 lives on the HUD
    search.run(press=["RIGHT"], frames=150)    # ...into a pit
    search.filter("decreased")
    for candidate in search.candidates():
        print(candidate.address, candidate.type, candidate.values)
    search.save_field("lives", 0xFF002B, "|u1", game_file="my-games/Dasher-Genesis/game.yaml")
    search.save("dasher.session")              # resume with RamSearch.load
    search.write_movie("to-the-pit.bk2")       # the inputs played, from Zone1.Act1

What it writes out of the search (the movie, a state, a field) is in :mod:`retrokit.ramsearch.keeping`.
"""

from __future__ import annotations

import io
import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Self

import numpy as np

from retrokit.data import statecheck
from retrokit.data.games import Game, find_game
from retrokit.data.roms import rom_sha1
from retrokit.data.script import MAX_FRAMES, Step, parse_script, port_masks, script_frames
from retrokit.data.states import StateRecord
from retrokit.errors import DataFileError, InvalidArgumentError, MovieError, SessionError, StateError
from retrokit.host.emulator import Emulator
from retrokit.host.typecodes import parse_type
from retrokit.paths import atomic_write
from retrokit.ramsearch.candidates import Candidate
from retrokit.ramsearch.engine import Engine, list_candidates
from retrokit.ramsearch.keeping import Keeping
from retrokit.ramsearch.ram import RamLayout
from retrokit.ramsearch.session import SessionData, read_session, write_session
from retrokit.ramsearch.types import parse_search_types

if TYPE_CHECKING:
    from retrokit.movie import Movie


_LABEL_SCRIPT = 80  # a snapshot's label shows this much of a script


class RamSearch(Keeping):
    """A RAM search on one game.

    Args:
        game: The game's name (or a :class:`~retrokit.data.games.Game`).
        state: The state to start from (by default the game's default state).
        types: The type codes to search (by default every type Gym Retro infers).
    """

    def __init__(self, game: str | Game, state: str | None = None, *, types: Sequence[str] | None = None) -> None:
        self._open(find_game(game) if isinstance(game, str) else game, types)
        self.state = state if state is not None else self.game.default_state
        try:
            if self.state is not None:
                self.load_state(self.state)
        except BaseException:
            self.close()
            raise
        self._restart()
        self.snapshot(f"new {self.state or 'power-on'}")

    def _open(self, game: Game, types: Sequence[str] | None) -> None:
        """Load the game's ROM into a new emulator, with an empty search over its RAM."""
        self.game = game
        self.rom = game.require_rom()
        self.rom_sha1 = rom_sha1(self.rom, game.system)
        self.emulator = Emulator(game.system, self.rom, ports=max(2, game.players))
        self.emulator.set_sticky(0.0, 0)
        self.layout = RamLayout.of(self.emulator.space)
        self.engine = Engine(self.layout, parse_search_types(types))
        self.labels: list[str] = []
        self.start_state = b""  # the state the inputs played begin at (b"": power-on)
        self.start_made_here = False  # whether this process's core serialized start_state (not read from a file)
        self.inputs: list[tuple[int, tuple[int, ...]]] = []  # runs: (frames, a mask per port)
        self.unreplayable: str | None = None  # why those inputs no longer lead to the state now

    def _restart(self) -> None:
        """Begin the inputs played afresh from the emulator's state now (a state was loaded)."""
        self.start_state, self.start_made_here = self.emulator.get_state(), True
        self.inputs, self.unreplayable = [], None

    def _played(self, masks: Sequence[int], frames: int) -> None:
        """Record ``frames`` frames holding ``masks`` (one per port)."""
        masks = tuple(int(m) for m in masks) + (0,) * (self.emulator.ports - len(masks))
        if not frames:
            return
        if self.inputs and self.inputs[-1][1] == masks and self.inputs[-1][0] + frames <= MAX_FRAMES:
            self.inputs[-1] = (self.inputs[-1][0] + frames, masks)
        else:
            self.inputs.append((frames, masks))

    # --- sessions ------------------------------------------------------------------------------

    @classmethod
    def load(cls, path: str | os.PathLike[str], *, game: str | None = None) -> RamSearch:
        """Resume a search from a session file.

        Args:
            path: The session file.
            game: If given, the game the session must be a search of.

        Raises:
            SessionError: The file is missing, corrupt, not a session, or of another game or ROM.
        """
        data = read_session(path)
        if game is not None and data.game != find_game(game).name:
            raise SessionError(
                f"Expected a session of {game} in {path}; found one of {data.game}. "
                "Pass another --session file, or start one for this game with: retrokit ramsearch new GAME --session FILE"
            )
        self = cls.__new__(cls)
        self._open(find_game(data.game), data.types)
        try:
            self._resume(path, data)
        except BaseException:
            self.close()
            raise
        return self

    def _resume(self, path: str | os.PathLike[str], data: SessionData) -> None:
        if self.rom_sha1 != data.rom_sha1:
            raise SessionError(
                f"Expected the ROM {path} was made with (SHA-1 {data.rom_sha1}) for {data.game}; found {self.rom} "
                f"with SHA-1 {self.rom_sha1}. The session belongs to another ROM: start a new one."
            )
        if self.layout.regions != data.regions:
            raise SessionError(
                f"{path}: expected RAM regions {self.layout.describe()}; found {RamLayout(data.regions).describe()}."
            )
        for row in data.snapshots:
            self.engine.add_snapshot(row)
        self.engine.candidates, self.engine.history, self.engine.redo_stack = data.candidates, data.history, data.redo
        self.labels, self.state = list(data.labels), data.state
        ports = self.emulator.ports
        if data.inputs.shape[1] != ports + 1:
            raise SessionError(f"{path}: expected inputs of {ports} ports; found {data.inputs.shape[1] - 1}.")
        self.start_state, self.unreplayable = data.start_state, data.unreplayable
        self.start_made_here = False  # the file's bytes: a movie from them is probed when replayed
        self.inputs = [(int(row[0]), tuple(int(m) for m in row[1:])) for row in data.inputs]
        try:
            # The record may refuse it (another ROM), never vouch for it: unless this machine
            # wrote or probed the state, it is first run in a child process.
            record = StateRecord(data.game, data.rom_sha1, data.state_sha256)
            self.emulator.set_state(
                statecheck.check_state(self.game, data.emulator_state, record, source=str(path), rom=self.rom)
            )
        except StateError as exc:
            raise SessionError(
                f"{path}: expected an emulator state of {data.game}; the core refused it ({exc})."
            ) from None

    def save(self, path: str | os.PathLike[str], *, overwrite: bool = True) -> None:
        """Write the session file (atomically).

        Raises:
            FileConflictError: ``path`` exists and ``overwrite`` is false.
        """
        data = self.session_data()
        statecheck.remember_written(self.game, data.emulator_state, self.rom)  # resuming it needs no probe
        write_session(path, data, overwrite=overwrite)

    def session_data(self) -> SessionData:
        """Everything a session file holds."""
        return SessionData(
            game=self.game.name,
            rom_sha1=self.rom_sha1,
            state=self.state,
            types=self.types,
            regions=self.layout.regions,
            emulator_state=self.emulator.get_state(),
            snapshots=np.stack(self.engine.snapshots),
            labels=list(self.labels),
            candidates=self.engine.candidates,
            history=list(self.engine.history),
            redo=list(self.engine.redo_stack),
            start_state=self.start_state,
            inputs=np.array([(frames, *masks) for frames, masks in self.inputs], dtype=np.uint32).reshape(
                -1, self.emulator.ports + 1
            ),
            unreplayable=self.unreplayable,
        )

    def close(self) -> None:
        """Close the emulator."""
        self.emulator.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- moving the game ------------------------------------------------------------------------

    @property
    def types(self) -> tuple[str, ...]:
        """The searched type codes."""
        return tuple(t.code for t in self.engine.types)

    def load_state(self, name: str) -> None:
        """Put the game in one of its save states (no snapshot is taken)."""
        self.emulator.set_state(statecheck.load_state(self.game, self.game.state_path(name)))
        self.emulator.forget_action()
        self._restart()

    def restart_inputs(self) -> None:
        """Begin the inputs played afresh from now, so :meth:`movie` records from this moment (a movie's start)."""
        self._restart()

    def snapshot(self, label: str = "snapshot") -> int:
        """Take a snapshot of the RAM now; return its index."""
        index = self.engine.add_snapshot(self.layout.read(self.emulator.space))
        self.labels.append(label)
        return index

    def buttons(self, press: Sequence[str]) -> list[int]:
        """The button mask of each port for names like ``RIGHT`` (port 1) or ``2:START``.

        Raises:
            UnknownNameError: A name is not one of the system's buttons.
        """
        return port_masks(self.emulator.system, self.emulator.ports, press)

    def step(self, press: Sequence[str] = (), frames: int = 1) -> None:
        """Hold buttons for some frames, without a snapshot (to script play between snapshots)."""
        if not isinstance(frames, int) or isinstance(frames, bool) or not 0 <= frames <= MAX_FRAMES:
            raise InvalidArgumentError(f"Expected a number of frames from 0 to {MAX_FRAMES:,}, got {frames!r}.")
        masks = self.buttons(press)
        self.emulator.run(masks, frames)
        self._played(masks, frames)

    def run(
        self, press: Sequence[str] = (), frames: int = 1, *, state: str | None = None, snapshot: bool = True
    ) -> int | None:
        """Hold buttons for some frames (from a state, if given), then take a snapshot; return its index.

        With ``snapshot=False`` the game moves on and no snapshot is taken (``None`` is returned).
        """
        self.buttons(press)  # unknown buttons fail before the state is loaded
        if state is not None:
            self.load_state(state)
        self.step(press, frames)
        held = " ".join(press) if press else "nothing"
        return self._snap(f"{'state ' + state + ', ' if state else ''}{held} for {frames} frames", snapshot)

    def run_script(self, script: str, *, state: str | None = None, snapshot: bool = True) -> int | None:
        """Play an input script (taps, holds and waits: see :mod:`retrokit.data.script`), then take a snapshot.

        Raises:
            InvalidArgumentError: The script is malformed or names an unknown button (all of it is checked first).
        """
        steps = parse_script(script, self.buttons)
        if state is not None:
            self.load_state(state)
        self.play_steps(steps)
        text = " ".join(script.split())
        text = text if len(text) <= _LABEL_SCRIPT else text[: _LABEL_SCRIPT - 3] + "..."
        label = f"{'state ' + state + ', ' if state else ''}script {text} ({script_frames(steps)} frames)"
        return self._snap(label, snapshot)

    def play_steps(self, steps: Sequence[Step]) -> None:
        """Play a parsed script's steps (each step's masks made once: a repeated step is one object)."""
        masks: dict[int, list[int]] = {}
        for step in steps:
            held = masks.get(id(step))
            if held is None:
                held = masks[id(step)] = self.buttons(step.buttons)
            self.emulator.run(held, step.frames)
            self._played(held, step.frames)

    def ram_frames(self, script: str | None = None, movie: str | os.PathLike[str] | None = None) -> Iterator[np.ndarray]:
        """The RAM now, then after each frame of a script, or of a movie from its start, played a frame at a time.

        The script or movie is checked now, before anything plays; it plays as the iterator is advanced.

        Raises:
            InvalidArgumentError: Neither or both are given, or the script is malformed.
            MovieError: The movie is malformed or of another game.
        """
        if (script is None) == (movie is None):
            raise InvalidArgumentError("Expected a script or a movie to play, one of them; got " +
                                       ("both." if script is not None else "neither."))  # fmt: skip
        if movie is not None:
            return (self.layout.read(self.emulator.space) for _ in self.replaying(movie)[1])
        steps = parse_script(script, self.buttons)

        def play() -> Iterator[np.ndarray]:
            yield self.layout.read(self.emulator.space)
            for step in steps:
                masks = self.buttons(step.buttons)
                for _ in range(step.frames):
                    self.emulator.run(masks, 1)
                    self._played(masks, 1)
                    yield self.layout.read(self.emulator.space)

        return play()

    def _snap(self, label: str, snapshot: bool) -> int | None:
        return self.snapshot(label) if snapshot else None

    def play(self, movie: str | os.PathLike[str], until: int | None = None, *, snapshot: bool = True) -> int | None:
        """Play a ``.bk2`` movie from its start up to frame ``until`` (all of it by default), then take a snapshot.

        Raises:
            MovieError: The movie is malformed or of another game.
        """
        _, frames = self.replaying(movie, until)
        end = 0
        for end in frames:
            pass
        return self._snap(f"movie {Path(movie).name} to frame {end}", snapshot)

    def replaying(self, movie: str | os.PathLike[str], until: int | None = None) -> tuple[Movie, Iterator[int]]:
        """Check a ``.bk2`` movie of this game, and play it lazily: one frame each time its iterator is advanced.

        The iterator is :func:`retrokit.movie.playback.replay`'s, so the start state
        goes through its check: it yields 0 once the console is at the movie's
        start, then each frame's number (1-based) once it has run, up to ``until``
        (all by default). From the start on, the inputs played are the movie's.

        Raises:
            MovieError: The movie is malformed or of another game (at once, before anything runs).
        """
        from retrokit.movie import read_bk2

        recorded = read_bk2(movie)
        if recorded.game != self.game.name:
            raise MovieError(
                f"Expected a movie of {self.game.name}; found one of {recorded.game} in {movie}. Record one of this game."
            )
        if recorded.players > self.emulator.ports:
            raise MovieError(
                f"Expected a movie of at most {self.emulator.ports} players; {movie} has {recorded.players}."
            )
        end = len(recorded.frames) if until is None else until
        if not isinstance(end, int) or not 0 <= end <= len(recorded.frames):
            raise InvalidArgumentError(
                f"Expected --until from 0 to the movie's {len(recorded.frames)} frames, got {until!r}."
            )
        return recorded, self._replay(recorded, str(movie), end)

    def _replay(self, recorded: Movie, source: str, end: int) -> Iterator[int]:
        from retrokit.movie.playback import replay

        frames = replay(recorded, self.emulator, source=source, stop=end)  # its start state checked there
        yield next(frames)
        # The inputs played now begin at the movie's start (b"": power-on), whatever replayed it.
        self.start_state, self.inputs, self.unreplayable = recorded.state or b"", [], None
        self.start_made_here = False  # checked by replay(): known safe already, or refused
        for number in frames:
            self._played(recorded.frames[number - 1], 1)
            yield number

    def poke(self, address: int, value: int, type_code: str = "|u1") -> None:
        """Write a value into RAM (the next snapshot sees it).

        Raises:
            FieldTypeError: The type code is unknown.
            InvalidArgumentError: The address is outside RAM, or the value does not fit the type.
        """
        ftype = parse_type(type_code)
        self.layout.position(address, ftype.width)
        if not isinstance(value, int) or isinstance(value, bool):
            raise InvalidArgumentError(f"Expected a whole number to poke, got {value!r}.")
        self.emulator.poke(address, value, type_code)
        self.unreplayable = f"poke {self.layout.format(address)} {value}"

    def screen(self) -> np.ndarray:
        """The screen of the next frame from here, emulated on a scratch run, so pokes show on it."""
        state = self.emulator.get_state()
        self.emulator.run(0, 1)
        picture = self.emulator.screen()
        self.emulator.set_state(state)
        return picture

    def screenshot(self, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
        """Save :meth:`screen` as a PNG.

        Raises:
            FileConflictError: ``path`` exists and ``overwrite`` is false.
        """
        from PIL import Image

        path = Path(path)
        buffer = io.BytesIO()
        Image.fromarray(self.screen()).save(buffer, format="PNG")
        atomic_write(path, buffer.getvalue(), overwrite=overwrite)
        return path

    # --- searching ------------------------------------------------------------------------------

    def new_search(self, types: Sequence[str] | None = None) -> int:
        """Start the search afresh from the game's moment now: every candidate back, one snapshot; return it.

        The game, its state and the inputs played stay as they are (a long-running session, such as
        the studio's, looks for one variable after another).

        Raises:
            FieldTypeError: A type code is unknown, or given twice.
        """
        self.engine = Engine(self.layout, parse_search_types(types if types is not None else self.types))
        self.labels = []
        return self.snapshot("new search")

    def reload_game(self) -> None:
        """Read the game's data files again, after its game.yaml was written (a field added or edited).

        A shipped game's first write made its copy in the data folder (:meth:`default_game_file`), which
        then comes first.
        """
        folders = self.game.folders
        try:
            written = self.default_game_file().parent
        except DataFileError:  # Gym Retro's format: nothing was written
            written = folders[0]
        if written not in folders and (written / "game.yaml").is_file():
            folders = (written, *folders)
        self.game = Game(self.game.name, folders).check()

    def filter(self, op: str, value: int | None = None, than: str | int | None = None) -> int:
        """Keep the candidates that pass a filter (see :mod:`retrokit.ramsearch.engine`); return how many are left."""
        return self.engine.filter(op, value, than)

    def undo(self) -> str:
        """Undo the last filter; return it."""
        return self.engine.undo()

    def redo(self) -> str:
        """Redo the last undone filter; return it."""
        return self.engine.redo()

    @property
    def count(self) -> int:
        """How many candidates are left."""
        return self.engine.candidates.count()

    @property
    def history(self) -> list[str]:
        """The filters applied, oldest first (undone ones are not listed)."""
        return [label for label, _ in self.engine.history]

    def candidates(self, limit: int | None = None) -> list[Candidate]:
        """The candidates by address (then simplest type first), at most ``limit`` of them."""
        return list_candidates(self.engine, limit)
