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
"""

from __future__ import annotations

import io
import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Self

import numpy as np

from retrokit import paths
from retrokit.data import statecheck
from retrokit.data.games import Game, find_game
from retrokit.data.names import check_state_name
from retrokit.data.roms import rom_sha1
from retrokit.data.script import MAX_FRAMES, parse_script, port_masks
from retrokit.data.states import StateRecord
from retrokit.errors import DataFileError, FileConflictError, InvalidArgumentError, MovieError, SessionError, StateError
from retrokit.host.emulator import Emulator
from retrokit.host.typecodes import parse_type
from retrokit.paths import atomic_write, ensure_folder, locked, wheel_dir
from retrokit.ramsearch import gamefile
from retrokit.ramsearch.candidates import Candidate
from retrokit.ramsearch.engine import Engine, list_candidates
from retrokit.ramsearch.ram import RamLayout
from retrokit.ramsearch.session import SessionData, read_session, write_session
from retrokit.ramsearch.types import BitType, parse_search_types, search_type

if TYPE_CHECKING:
    from retrokit.data.integrate import Outcome
    from retrokit.movie import Movie


_LABEL_SCRIPT = 80  # a snapshot's label shows this much of a script


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
        self.inputs: list[tuple[int, tuple[int, ...]]] = []  # runs: (frames, a mask per port)
        self.unreplayable: str | None = None  # why those inputs no longer lead to the state now

    def _restart(self) -> None:
        """Begin the inputs played afresh from the emulator's state now (a state was loaded)."""
        self.start_state = self.emulator.get_state()
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
        for step in steps:
            self.step(step.buttons, step.frames)
        text = " ".join(step.describe() for step in steps)
        frames = sum(step.frames for step in steps)
        text = text if len(text) <= _LABEL_SCRIPT else text[: _LABEL_SCRIPT - 3] + "..."
        label = f"{'state ' + state + ', ' if state else ''}script {text} ({frames} frames)"
        return self._snap(label, snapshot)

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
        """Read the game's data files again, after its game.yaml was written (a field added or edited)."""
        self.game = Game(self.game.name, self.game.folders).check()

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

    # --- saving the game's state and the inputs played ------------------------------------------------

    def movie(self) -> Movie:
        """The inputs played since the last state loaded (or the start), as a movie from that state.

        Raises:
            MovieError: A poke changed RAM since that state, which no input can reproduce.
        """
        from retrokit.movie import Movie

        if self.unreplayable is not None:
            raise MovieError(
                f"Expected inputs that lead to the game's state now; the session changed RAM by hand since its "
                f"start state ({self.unreplayable}), which a movie cannot reproduce. Start from a state again "
                "(ramsearch run --state NAME), play without poking, then write the movie."
            )
        total = sum(count for count, _ in self.inputs)
        if total > MAX_FRAMES:
            raise MovieError(
                f"Expected at most {MAX_FRAMES:,} frames for a movie; the session played {total:,} since its start "
                "state. Save a state on the way (ramsearch savestate) and start from it."
            )
        used = [port for _, masks in self.inputs for port, mask in enumerate(masks, 1) if mask]
        players = max([self.game.players, *used])
        frames = [masks[:players] for count, masks in self.inputs for _ in range(count)]
        return Movie(self.game.name, self.game.system.name, players, self.start_state or None, frames)

    def write_movie(self, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
        """Write :meth:`movie` as a stable-retro ``.bk2`` (for ``retrokit integrate --movie`` and ``validate``).

        Raises:
            MovieError: A poke changed RAM since the start state.
            FileConflictError: A different file is at ``path`` and ``overwrite`` is false.
        """
        from retrokit.movie import write_bk2

        write_bk2(path, self.movie(), overwrite=overwrite)
        return Path(path)

    def save_state(self, name: str, *, default: bool = False, force: bool = False) -> Outcome:
        """Save the emulator's state now as state ``name`` of the game, where ``retrokit integrate`` writes.

        It goes to ``<data>/games/<Game>/NAME.state`` (with its record), or next to a game.yaml of
        the user's own outside every games folder. With ``default``, ``states: default: NAME`` is
        written into that folder's game.yaml, so ``make(game)`` starts from it; a game whose
        game.yaml is elsewhere gets a copy of it there first (which then overrides it).

        Returns:
            What was done: ``"made"``, ``"up to date"`` or ``"replaced"`` (see :func:`~retrokit.data.integrate.place_state`).

        Raises:
            InvalidArgumentError: ``name`` is not a valid state name.
            FileConflictError: A different state of that name exists and ``force`` is false.
            DataFileError: ``default`` and the game's data file is not a game.yaml.
        """
        from retrokit.data.integrate import place_state, target_folder

        check_state_name(name)
        folder = target_folder(self.game)
        game_file = folder / "game.yaml"
        if default and not game_file.exists():
            self._check_own_game_yaml()
        outcome = place_state(self.game, name, self.emulator.get_state(), folder, force=force)
        if outcome.status in ("differs", "damaged"):
            kind = "a different state" if outcome.status == "differs" else "a file the core cannot load"
            raise FileConflictError(
                f"Expected no state {name!r} of {self.game.name} or the same one; found {kind} at {outcome.path}. "
                "Pass --force (force=True) to replace it, or choose another name."
            )
        if default:
            self._write_default_state(game_file, name)
        return outcome

    def set_default_state(self, name: str) -> Path:
        """Make state ``name`` the game's default (``states: default: NAME``), as ``save_state(default=True)`` does.

        Returns:
            The game.yaml written.

        Raises:
            InvalidArgumentError: ``name`` is not a valid state name.
            StateNotFoundError: The game has no state of that name.
            DataFileError: The game's data file is not a game.yaml.
        """
        from retrokit.data.integrate import target_folder

        check_state_name(name)
        self.game.state_path(name)  # one of its states, or a StateNotFoundError with a did-you-mean
        game_file = target_folder(self.game) / "game.yaml"
        if not game_file.exists():
            self._check_own_game_yaml()
        self._write_default_state(game_file, name)
        return game_file

    def _write_default_state(self, game_file: Path, name: str) -> None:
        ensure_folder(game_file.parent, "to write the game's game.yaml into")
        with locked(game_file):  # two writers making the copy at once: the second edits the first's copy
            if not game_file.exists():
                atomic_write(game_file, self.game.info.source.read_bytes())
            gamefile.set_default_state(game_file, name)

    def restart_inputs(self) -> None:
        """Begin the inputs played afresh from now, so :meth:`movie` records from this moment (a movie's start)."""
        self._restart()

    def _check_own_game_yaml(self) -> None:
        if self.game.info.source.name != "game.yaml":
            raise DataFileError(
                f"Expected {self.game.name} to have a game.yaml to write its default state into; its data file is "
                f"{self.game.info.source}, in Gym Retro's format. Pass the state by name instead: make(game, state=NAME)."
            )

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
        value_range: tuple[int, int] | None = None,
    ) -> Path:
        """Write a field into a game.yaml, keeping its comments and layout; return the file.

        Args:
            name: The field's name.
            address: Its console address.
            type_code: Its type code; a bit type (``|u1&0x04``) is written as ``type: "|u1", mask: 0x04``.
            game_file: The game.yaml to write (by default :meth:`default_game_file`).
            force: Replace a field of the same name.
            value_range: The values it may hold, ``(lo, hi)``, written as ``range: [lo, hi]``.

        Raises:
            FieldTypeError: The type code is unknown.
            InvalidArgumentError: The address is outside RAM, the name is not a valid field name, or
                the range is not two whole numbers ``lo <= hi`` the type can hold.
            SessionError: ``game_file`` is the data file of another game.
            FileConflictError: The file has a field of that name and ``force`` is false.
        """
        gamefile.check_field_name(name)  # first: a bad name is the name's fault, not the file's
        ftype = search_type(type_code)
        self.layout.position(address, ftype.width)
        if value_range is not None:
            value_range = gamefile.check_range(value_range, ftype)
        path = Path(game_file) if game_file is not None else self.default_game_file()
        if game_file is not None:
            self._check_game_file(path)
        bit = isinstance(ftype, BitType)
        gamefile.add_field(path, name, self.layout.format(address), ftype.base if bit else ftype.code, force=force,
                           value_range=value_range, mask=ftype.mask if bit else None)  # fmt: skip
        return path

    def _check_game_file(self, path: Path) -> None:
        from retrokit.data.gamefiles import read_game_yaml

        if not path.is_file():  # a FIFO or a device is not one either
            raise DataFileError(
                f"Expected a game.yaml at {path}; found no file. Give the path of an existing game.yaml."
            )
        sha1s = read_game_yaml(path).sha1s
        if sha1s and self.rom_sha1 not in sha1s:
            raise SessionError(
                f"Expected a game.yaml of {self.game.name} (ROM SHA-1 {self.rom_sha1}); {path} lists other ROMs "
                f"({', '.join(sha1s)}): it is another game's. Pass the game.yaml of {self.game.name}."
            )
