"""Deciding whether a save state may be loaded into an emulator in this process: the checked load.

Every state reaches a core as a :class:`~retrokit.host.emulator.VettedState`,
and these functions are how one is made from a file or from bytes:

- a state retrokit recorded (:class:`~retrokit.data.states.StateRecord`) for a
  ROM the game does not accept is refused, naming the game it is for; one
  without a record that sits in another game's folder (where stable-retro keeps
  each game's states) is refused too, unless the two games share a ROM. The
  record only ever refuses: anyone can write one;
- whether the state may crash the core is decided by :func:`retrokit.data.probe.vet_state`,
  from what this machine wrote or probed and what the package ships, never
  from the file itself.
"""

from __future__ import annotations

import functools
import hashlib
import os
from pathlib import Path

from retrokit import paths
from retrokit.data.games import Game, cached_rom_sha1, load_game
from retrokit.data.probe import remember
from retrokit.data.probe import vet_state as _vet
from retrokit.data.shipped import STATE_HASHES
from retrokit.data.states import StateRecord, read_state_file
from retrokit.errors import RetrokitError, StateError
from retrokit.host.emulator import VettedState
from retrokit.host.systems import System, get_system


def check_state(
    game: Game, data: bytes, record: StateRecord | None = None, *, source: str, rom: Path | None = None,
    shipped: Path | None = None,
) -> VettedState:
    """Refuse a state that is for another game's ROM, or that crashes or hangs the core; return it checked.

    Args:
        game: The game the state is to be loaded for.
        data: The serialized state.
        record: What the file says retrokit recorded with the state, if anything (used only to refuse).
        source: What to call the state in errors (its path, or a movie's ``Core.bin``).
        rom: The ROM it will run on; by default the game's.
        shipped: The file ``data`` was read from, which needs no probe if it is a shipped state file.

    Raises:
        StateError: The state is for another ROM, or the core cannot run it.
        RomNotFoundError: The game's ROM is not available.
    """
    rom = rom if rom is not None else game.require_rom()
    rom_sha1 = cached_rom_sha1(rom, game.system)
    if record is not None and record.rom_sha1 != rom_sha1 and record.rom_sha1 not in game.sha1s:
        of = f", of {record.game}" if record.game != game.name else ""
        raise StateError(
            f"{source}: expected a state of {game.name} (ROM SHA-1 {rom_sha1}); found a state retrokit "
            f"recorded on another ROM (SHA-1 {record.rom_sha1}{of}). Load it with the game of that ROM, "
            f"or pick a state of {game.name}."
        )
    _check_identity(game, data, rom_sha1, source)
    return _vet(data, game.system, rom, rom_sha1, source=source, shipped=shipped)


def _check_identity(game: Game, data: bytes, rom_sha1: str, source: str) -> None:
    """Refuse a state retrokit ships for another game (on another ROM), known by its digest.

    Whatever file holds it, with its record stripped or a movie's header
    rewritten around it, a shipped state is known by its digest. (A record
    that no longer describes its state only loses its say: the state is
    probed, as a state changed since is.)
    """
    digest = hashlib.sha256(data).hexdigest()
    owner = _shipped_owners().get(digest)
    if owner is None or owner == game.name:
        return
    try:
        owner_sha1s = set(load_game(paths.repo_games_dir() / owner).sha1s)  # type: ignore[operator]
    except RetrokitError:
        return
    if owner_sha1s & ({rom_sha1} | set(game.sha1s)):
        return  # two games on one ROM: the state fits both
    raise StateError(
        f"{source}: expected a state of {game.name}; found {owner}'s state (retrokit ships it, SHA-256 "
        f"{digest[:16]}…), made on another ROM, where it plays garbage. Load it with {owner}, or pick a state "
        f"of {game.name}."
    )


@functools.cache
def _shipped_owners() -> dict[str, str]:
    """The digest of the state in every ``.state`` file retrokit's ``games/`` ships, to its game's name."""
    games = paths.repo_games_dir()
    owners: dict[str, str] = {}
    if games is None:
        return owners
    try:
        listed = (games / STATE_HASHES).read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return owners
    for line in listed:
        parts = line.split(maxsplit=1)
        if len(parts) != 2 or "/" not in parts[1]:
            continue
        try:
            owners[hashlib.sha256(read_state_file(games / parts[1]).data).hexdigest()] = parts[1].split("/")[0]
        except RetrokitError:
            continue  # a shipped file missing or damaged here: it identifies nothing
    return owners


def load_state(game: Game, path: str | os.PathLike[str]) -> VettedState:
    """Read a ``.state`` file for ``game`` and return the state, once it is known to be safe to load.

    Raises:
        StateError: The file is not a valid state, is for another game's ROM, or crashes the core.
    """
    path = Path(path)
    state = read_state_file(path)
    if state.record is None:
        _check_folder(game, path)
    return check_state(game, state.data, state.record, source=str(path), shipped=path)


def vet_state(
    data: bytes, system: str | System, rom: str | os.PathLike[str], *, source: str = "the state",
    shipped: str | os.PathLike[str] | None = None,
) -> VettedState:
    """Check a state for a ROM of no known game (or any ROM): probe it unless this machine knows it is safe.

    Args:
        data: The serialized state.
        system: The system (a name or descriptor).
        rom: The ROM it will run on.
        source: What to call it in errors.
        shipped: The ``.state`` file ``data`` was read from: no probe if its bytes are a shipped file's.

    Raises:
        StateError: The core cannot run it.
    """
    system = get_system(system)
    return _vet(data, system, rom, cached_rom_sha1(Path(rom), system), source=source, shipped=shipped)


def remember_written(game: Game, state: VettedState, rom: Path | None = None) -> None:
    """Note that retrokit wrote ``state`` (a core made it), so reading it back from its file needs no probe."""
    remember(state, cached_rom_sha1(rom if rom is not None else game.require_rom(), game.system))


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

