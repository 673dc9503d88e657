"""Deciding whether a save state may be loaded into an emulator in this process.

A state is loaded only if it is for the game's ROM and cannot crash the core:

- a state retrokit wrote records the game and the SHA-1 of its ROM
  (:class:`~retrokit.data.states.StateRecord`); one recorded for a ROM the game
  does not accept is refused, naming the game it is for; one without a record
  that sits in another game's folder (where stable-retro keeps each game's
  states) is refused too, unless the two games share a ROM;
- a state that is exactly what retrokit recorded, or that ships with retrokit
  or the stable-retro wheel, is trusted as it is;
- any other state (a user's, stable-retro's, one changed since retrokit wrote
  it) is first run in a child process, once per machine
  (:func:`retrokit.data.probe.vet_state`).
"""

from __future__ import annotations

from pathlib import Path

from retrokit import paths
from retrokit.data.games import Game, cached_rom_sha1, load_game
from retrokit.data.probe import vet_state
from retrokit.data.states import StateRecord, read_state_file
from retrokit.errors import RetrokitError, StateError


def is_shipped(path: Path) -> bool:
    """Whether ``path`` is one of the states retrokit's ``games/`` or the stable-retro wheel ship."""
    roots = [d for d in (paths.repo_games_dir(), *paths.wheel_data_dirs()) if d is not None]
    try:
        resolved = path.resolve()
    except OSError:
        return False
    return any(resolved.is_relative_to(root.resolve()) for root in roots)


def check_state(
    game: Game, data: bytes, record: StateRecord | None, *, source: str, rom: Path | None = None, trusted: bool = False
) -> None:
    """Refuse a state that is for another game's ROM, or that crashes or hangs the core.

    Args:
        game: The game the state is to be loaded for.
        data: The serialized state.
        record: What retrokit recorded with the state, if anything.
        source: What to call the state in errors (its path, or a movie's ``Core.bin``).
        rom: The ROM it will run on; by default the game's.
        trusted: The state ships with retrokit or the wheel: no probe.

    Raises:
        StateError: The state is for another ROM, or the core cannot run it.
        RomNotFoundError: The game's ROM is not available.
    """
    rom = rom if rom is not None else game.require_rom()
    rom_sha1 = cached_rom_sha1(rom, game.system)
    if record is not None:
        if record.rom_sha1 != rom_sha1 and record.rom_sha1 not in game.sha1s:
            of = f", of {record.game}" if record.game != game.name else ""
            raise StateError(
                f"{source}: expected a state of {game.name} (ROM SHA-1 {rom_sha1}); found a state retrokit "
                f"recorded on another ROM (SHA-1 {record.rom_sha1}{of}). Load it with the game of that ROM, "
                f"or pick a state of {game.name}."
            )
        if record.rom_sha1 == rom_sha1 and record.describes(data):
            return  # exactly what retrokit wrote for this ROM
    if not trusted:
        vet_state(data, game.system, rom, rom_sha1, source=source)


def load_state(game: Game, path: str | Path) -> bytes:
    """Read a ``.state`` file for ``game`` and return the state, once it is known to be safe to load.

    Raises:
        StateError: The file is not a valid state, is for another game's ROM, or crashes the core.
    """
    path = Path(path)
    state = read_state_file(path)
    if state.record is None:
        _check_folder(game, path)
    check_state(game, state.data, state.record, source=str(path), trusted=is_shipped(path))
    return state.data


def folder_game(path: Path) -> Game | None:
    """The game whose integration folder holds the file ``path``, or ``None`` if its folder is no game's."""
    try:
        return load_game(path.resolve().parent)
    except (RetrokitError, OSError):
        return None


def _check_folder(game: Game, path: Path) -> None:
    """Refuse a state kept in another game's folder, as stable-retro keeps each game's states, unless the two share a ROM."""
    owner = folder_game(path)
    if owner is None or owner.name == game.name or set(owner.sha1s) & set(game.sha1s):
        return
    raise StateError(
        f"{path}: expected a state of {game.name}; found one in the folder of {owner.name}, a game on another "
        f"ROM, where it plays garbage. Load it with {owner.name}, or pick a state of {game.name}."
    )

