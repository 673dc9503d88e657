"""What a RAM search keeps of what it found: the inputs played, the game's state, a field.

:class:`Keeping` is the half of :class:`~retrokit.ramsearch.search.RamSearch`
that writes outside the search: the inputs played since the last state
loaded as a ``.bk2`` movie from that state, the emulator's state as a state
of the game (and its default), and a variable found as a field of a
game.yaml. The other half (:mod:`retrokit.ramsearch.search`) moves the game,
narrows the candidates and keeps the session.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

from retrokit import paths
from retrokit.data.names import check_state_name
from retrokit.data.script import MAX_FRAMES
from retrokit.errors import DataFileError, FileConflictError, MovieError, SessionError
from retrokit.paths import atomic_write, ensure_folder, locked, wheel_dir
from retrokit.ramsearch import gamefile
from retrokit.ramsearch.types import BitType, search_type

if TYPE_CHECKING:
    from retrokit.data.games import Game
    from retrokit.data.integrate import Outcome
    from retrokit.host.emulator import Emulator
    from retrokit.movie import Movie
    from retrokit.ramsearch.ram import RamLayout


class Keeping:
    """Writing what a search found: the movie of its inputs, the game's state, a field (mixed into ``RamSearch``)."""

    # Set by RamSearch when it opens the game.
    game: Game
    rom: Path
    rom_sha1: str
    emulator: Emulator
    layout: RamLayout
    start_state: bytes  # the state the inputs played begin at (b"": power-on)
    start_made_here: bool  # whether this process's core serialized start_state
    inputs: list[tuple[int, tuple[int, ...]]]  # runs: (frames, a mask per port)
    unreplayable: str | None  # why those inputs no longer lead to the state now

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
        from retrokit.data.statecheck import remember_written
        from retrokit.movie import write_bk2

        movie = self.movie()
        write_bk2(path, movie, overwrite=overwrite)
        if self.start_made_here and movie.state:  # the core wrote it here: replaying the movie needs no probe
            remember_written(self.game, movie.state, self.rom)  # (which took 2 CPU-s, 12 s on a loaded machine)
        return Path(path)

    def save_state(self, name: str, *, default: bool = False, force: bool = False) -> Outcome:
        """Save the emulator's state now as state ``name`` of the game, where ``retrokit integrate`` writes.

        It goes to ``<data>/games/<Game>/NAME.state`` (with its record), or next to a game.yaml of
        the user's own outside every games folder. With ``default``, ``states: default: NAME`` is
        written into the game's game.yaml (:meth:`default_game_file`: a shipped game's is copied
        into the data folder first), so ``make(game)`` starts from it.

        Returns:
            What was done: ``"made"``, ``"up to date"`` or ``"replaced"`` (see :func:`~retrokit.data.integrate.place_state`).

        Raises:
            InvalidArgumentError: ``name`` is not a valid state name.
            FileConflictError: A different state of that name exists and ``force`` is false.
            DataFileError: ``default`` and the game's data file is not a game.yaml.
        """
        from retrokit.data.integrate import place_state, target_folder

        check_state_name(name)
        game_file = self.default_game_file() if default else None  # a Gym Retro game refuses before any write
        outcome = place_state(self.game, name, self.emulator.get_state(), target_folder(self.game), force=force)
        if outcome.status in ("differs", "damaged"):
            kind = "a different state" if outcome.status == "differs" else "a file the core cannot load"
            raise FileConflictError(
                f"Expected no state {name!r} of {self.game.name} or the same one; found {kind} at {outcome.path}. "
                "Pass --force (force=True) to replace it, or choose another name."
            )
        if game_file is not None:
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
        check_state_name(name)
        self.game.state_path(name)  # one of its states, or a StateNotFoundError with a did-you-mean
        game_file = self.default_game_file()
        self._write_default_state(game_file, name)
        return game_file

    def _write_default_state(self, game_file: Path, name: str) -> None:
        gamefile.set_default_state(self._copied(game_file), name)

    def _copied(self, game_file: Path) -> Path:
        """``game_file``, once it exists: the copy-first rule (:meth:`default_game_file`), made under the folder's lock
        (two writers making the copy at once: the second edits the first's copy)."""
        ensure_folder(game_file.parent, "to write the game's game.yaml into")
        with locked(game_file):
            if not game_file.exists():
                atomic_write(game_file, self.game.info.source.read_bytes())
        return game_file

    # --- saving a find --------------------------------------------------------------------------

    def default_game_file(self) -> Path:
        """The game.yaml this game's finds and default state are written into: the one rule of them all.

        The game's own game.yaml where it is the user's (a folder in ``RETROKIT_GAMES``, the data
        folder's ``games/``, a game.yaml outside every games folder); for a game retrokit ships (the
        checkout's ``games/``, the installed package, stable-retro's wheel), its copy in
        ``<data>/games/<Game>/game.yaml``, which overrides the shipped one once written (the writers
        make it first). Nothing a user did not make is edited in place.

        Raises:
            DataFileError: The game's data file is not a game.yaml (Gym Retro's format).
            PlantedLinkError: The file, or a folder on its way in the data folder, is a symlink.
        """
        source = self.game.info.source
        if source.name != "game.yaml":
            raise DataFileError(
                f"Expected {self.game.name} to have a game.yaml to write into; its data file is {source}, in Gym "
                "Retro's format, which this tool does not edit. Pass --game-file PATH (game_file=) of a game.yaml of "
                f"yours (a copy of the game's folder in a folder named in {paths.GAMES_ENV}), or a state by name "
                "instead of a default (make(game, state=NAME))."
            )
        shipped = [p.resolve() for p in (wheel_dir(), paths.repo_games_dir(), Path(paths.__file__).parent) if p]
        if any(source.resolve().is_relative_to(p) for p in shipped):
            return paths.data_path("games", self.game.name, "game.yaml")
        return paths.inside_data(source)  # a game folder of the data folder's is written there, never through a link

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
            game_file: The game.yaml to write (by default :meth:`default_game_file`, copied first for a shipped game).
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
        path = Path(game_file) if game_file is not None else self._copied(self.default_game_file())
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
