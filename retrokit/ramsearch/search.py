"""``RamSearch``: a RAM search on a running game, in the spirit of BizHawk's and Gym Retro's.

Start from a save state, move the game between snapshots (hold buttons for
some frames, play a ``.bk2`` movie, poke a value), narrow the candidates with
filters, look at them, and write the one you found into the game's
``game.yaml``::

    from retrokit.ramsearch import RamSearch

    search = RamSearch("Dasher-Genesis", "Zone1.Act1")
    search.filter("equal", 3)                  # 3 lives on the HUD
    search.run(press=["RIGHT"], frames=150)    # ...into a pit
    search.filter("decreased")
    for candidate in search.candidates():
        print(candidate.address, candidate.type, candidate.values)
    search.save_field("lives", 0xFF002B, "|u1", game_file="my-games/Dasher-Genesis/game.yaml")
    search.save("dasher.session")              # resume with RamSearch.load
"""

from __future__ import annotations

import io
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Self

import numpy as np

from retrokit import paths
from retrokit.data import statecheck
from retrokit.data.games import Game, find_game
from retrokit.data.roms import rom_sha1
from retrokit.data.states import StateRecord
from retrokit.errors import DataFileError, InvalidArgumentError, MovieError, SessionError, StateError
from retrokit.host.emulator import Emulator
from retrokit.host.typecodes import parse_type
from retrokit.paths import atomic_write, wheel_dir
from retrokit.ramsearch import gamefile
from retrokit.ramsearch.candidates import Candidate, list_candidates
from retrokit.ramsearch.engine import Engine
from retrokit.ramsearch.ram import RamLayout
from retrokit.ramsearch.session import SessionData, read_session, write_session
from retrokit.ramsearch.types import parse_search_types


class RamSearch:
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
        masks = [0] * self.emulator.ports
        for name in press:
            port, _, button = name.rpartition(":")
            index = int(port) - 1 if port.isdigit() else 0
            if port and not port.isdigit() or not 0 <= index < len(masks):
                raise InvalidArgumentError(
                    f"Expected a button, or PORT:BUTTON with a port of 1 to {len(masks)}; got {name!r}."
                )
            masks[index] |= self.emulator.system.mask([button])
        return masks

    def step(self, press: Sequence[str] = (), frames: int = 1) -> None:
        """Hold buttons for some frames, without a snapshot (to script play between snapshots)."""
        if not isinstance(frames, int) or frames < 0:
            raise InvalidArgumentError(f"Expected a number of frames of 0 or more, got {frames!r}.")
        self.emulator.run(self.buttons(press), frames)

    def run(self, press: Sequence[str] = (), frames: int = 1, *, state: str | None = None) -> int:
        """Hold buttons for some frames (from a state, if given), then take a snapshot; return its index."""
        self.buttons(press)  # unknown buttons fail before the state is loaded
        if state is not None:
            self.load_state(state)
        self.step(press, frames)
        held = " ".join(press) if press else "nothing"
        return self.snapshot(f"{'state ' + state + ', ' if state else ''}{held} for {frames} frames")

    def play(self, movie: str | os.PathLike[str], until: int | None = None) -> int:
        """Play a ``.bk2`` movie from its start up to frame ``until`` (all of it by default), then take a snapshot.

        Raises:
            MovieError: The movie is malformed or of another game.
        """
        from retrokit.movie import read_bk2
        from retrokit.movie.playback import replay

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
        for _ in replay(recorded, self.emulator, source=str(movie), stop=end):  # its start state checked there
            pass
        return self.snapshot(f"movie {Path(movie).name} to frame {end}")

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

    # --- saving a find --------------------------------------------------------------------------

    def default_game_file(self) -> Path:
        """The game.yaml ``save_field`` writes to by default: the game's own.

        Raises:
            DataFileError: The game's data file is not a game.yaml (a Gym Retro folder), or is inside stable-retro.
        """
        source = self.game.info.source
        installed = [p.resolve() for p in (wheel_dir(), Path(paths.__file__).parent) if p is not None]
        if source.name != "game.yaml" or any(source.resolve().is_relative_to(p) for p in installed):
            raise DataFileError(
                f"Expected {self.game.name} to have its own game.yaml; its data file is {source}, inside an "
                "installed package or in Gym Retro's format, which this tool does not edit. Copy the game's folder "
                f"into a folder named in {paths.GAMES_ENV} and pass --game-file PATH (game_file=) to its game.yaml."
            )
        return source

    def save_field(
        self,
        name: str,
        address: int,
        type_code: str,
        *,
        game_file: str | os.PathLike[str] | None = None,
        force: bool = False,
    ) -> Path:
        """Write a field into a game.yaml, keeping its comments and layout; return the file.

        Raises:
            FieldTypeError: The type code is unknown.
            InvalidArgumentError: The address is outside RAM, or the name is not a valid field name.
            SessionError: ``game_file`` is the data file of another game.
            FileConflictError: The file has a field of that name and ``force`` is false.
        """
        ftype = parse_type(type_code)
        self.layout.position(address, ftype.width)
        path = Path(game_file) if game_file is not None else self.default_game_file()
        if game_file is not None:
            self._check_game_file(path)
        gamefile.add_field(path, name, self.layout.format(address), ftype.code, force=force)
        return path

    def _check_game_file(self, path: Path) -> None:
        from retrokit.data.gamefiles import read_game_yaml

        if not path.is_file():
            raise DataFileError(
                f"Expected a game.yaml at {path}; found no file. Give the path of an existing game.yaml."
            )
        sha1s = read_game_yaml(path).sha1s
        if sha1s and self.rom_sha1 not in sha1s:
            raise SessionError(
                f"Expected a game.yaml of {self.game.name} (ROM SHA-1 {self.rom_sha1}); {path} lists other ROMs "
                f"({', '.join(sha1s)}): it is another game's. Pass the game.yaml of {self.game.name}."
            )
