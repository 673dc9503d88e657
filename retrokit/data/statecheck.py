"""Deciding whether a save state may be loaded into an emulator in this process: the checked load.

Every state reaches a core as a :class:`~retrokit.host.emulator.VettedState`,
and these functions are how one is made from a file or from bytes:

- a state retrokit recorded (:class:`~retrokit.data.states.StateRecord`) for a
  ROM the game does not accept is refused, naming the game it is for; one
  without a record that sits in another game's folder (where stable-retro keeps
  each game's states) is refused too, unless the two games share a ROM. The
  record only ever refuses: anyone can write one;
- a state known to be another game's (:func:`state_owners`), whatever file
  holds it (a ``.state`` file, its record stripped or rewritten, a movie's
  ``Core.bin``), is refused by its digest: this machine records the game of
  each state it writes (``<data>/state-owners/``), and the states retrokit
  and the stable-retro wheel ship are listed with their games
  (:mod:`retrokit.data.shipped`);
- whether the state may crash the core is decided by :func:`retrokit.data.probe.vet_state`,
  from what this machine wrote or probed and what the package ships, never
  from the file itself.
"""

from __future__ import annotations

import functools
import hashlib
import os
from dataclasses import dataclass
from pathlib import Path

from retrokit import paths
from retrokit.data.games import Game, cached_rom_sha1, load_game
from retrokit.data.probe import remember
from retrokit.data.probe import vet_state as _vet
from retrokit.data.shipped import STATE_HASHES, WHEEL_STATE_HASHES, wheel_state_files
from retrokit.data.states import MAX_STATE_FILE_SIZE, StateRecord, read_state_file
from retrokit.errors import RetrokitError, StateError
from retrokit.host.emulator import VettedState
from retrokit.host.systems import System, get_system

OWNERS = "state-owners"
"""The data folder's records of the states this machine wrote: ``<sha256 of the state>`` holds ``<ROM SHA-1> <game>``."""


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
    check_identity(game, data, rom_sha1, source, shipped)
    return _vet(data, game.system, rom, rom_sha1, source=source, shipped=shipped)


@dataclass(frozen=True)
class Owner:
    """The game a state is known to be for, and how it is known.

    Attributes:
        game: The game's name.
        sha1s: The SHA-1s of the ROMs it runs on.
        known: How it is known, for the error ("retrokit ships it", "this machine saved it ...").
    """

    game: str
    sha1s: frozenset[str]
    known: str


def state_owners(data: bytes, file: Path | None = None) -> list[Owner]:
    """The games the state ``data`` is known to be for (none, mostly one): by what this machine recorded when it
    wrote the state, by retrokit's shipped states, or by the stable-retro wheel's (``file``: the file it was read
    from, known by its digest if it is one of the wheel's).

    Each of these only ever refuses a state for another game; none makes a state trusted.
    """
    digest = hashlib.sha256(data).hexdigest()
    owners = [_recorded_owner(digest), _shipped_owner(_shipped_states().get(digest))]
    owners += [_wheel_owner(where) for where in _wheel_states().get(digest, ())]
    if file is not None and not any(owners):
        try:
            with open(file, "rb") as f:
                blob = f.read(MAX_STATE_FILE_SIZE + 1)
        except OSError:
            blob = b""
        owners += [_wheel_owner(where) for where in wheel_state_files().get(hashlib.sha256(blob).hexdigest(), ())]
    return [owner for owner in owners if owner is not None]


def check_identity(game: Game, data: bytes, rom_sha1: str, source: str, file: Path | None = None) -> None:
    """Refuse a state known to be another game's (see :func:`state_owners`), unless the two games share a ROM.

    Whatever file holds it, with its record stripped or a movie's header
    rewritten around it, a state is known by its digest. (A record in the file
    that no longer describes its state only loses its say: the state is
    probed, as a state changed since is.)
    """
    owners = state_owners(data, file)
    accepted = {rom_sha1} | set(game.sha1s)
    if not owners or any(owner.game == game.name or owner.sha1s & accepted for owner in owners):
        return  # unknown, its own game's, or a game's on the same ROM: the state fits
    owner = owners[0]
    raise StateError(
        f"{source}: expected a state of {game.name}; found {owner.game}'s state ({owner.known}, SHA-256 "
        f"{hashlib.sha256(data).hexdigest()[:16]}…), made on another ROM, where it plays garbage. Load it with "
        f"{owner.game}, or pick a state of {game.name}."
    )


def _owner_file(digest: str) -> Path:
    return paths.records_dir(OWNERS) / digest  # never through a link: a planted record would vouch


def _record_owner(game: Game, state: bytes, rom_sha1: str) -> None:
    """Note in the data folder that this machine wrote ``state`` from a core running ``game``'s ROM."""
    try:
        text = f"{rom_sha1} {game.name}\n".encode()
        paths.atomic_write(_owner_file(hashlib.sha256(state).hexdigest()), text, overwrite=True)
    except (OSError, RetrokitError):
        pass  # an unwritable data folder only means this state is not known as its game's


def _recorded_owner(digest: str) -> Owner | None:
    try:
        text = paths.read_regular_file(_owner_file(digest), "a state's owner record", 512, follow=False)
        rom_sha1, name = text.decode("utf-8").split(maxsplit=1)
    except (RetrokitError, UnicodeDecodeError, ValueError):
        return None
    name = name.strip()
    return Owner(name, frozenset({rom_sha1}), f"this machine saved it for {name}")


def _game_sha1s(folder: Path) -> frozenset[str]:
    try:
        return frozenset(load_game(folder).sha1s)
    except RetrokitError:
        return frozenset()


@functools.cache
def _shipped_states() -> dict[str, Path]:
    """The digest of the state in every ``.state`` file retrokit's ``games/`` ships, to its game's folder.

    Only the states are read here: a game's ROMs are looked up for the one digest that matches
    (:func:`_shipped_owner`), so a process that loads one state does not parse every game's files.
    """
    games = paths.repo_games_dir()
    found: dict[str, Path] = {}
    if games is None:
        return found
    try:
        listed = (games / STATE_HASHES).read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return found
    for line in listed:
        parts = line.split(maxsplit=1)
        if len(parts) != 2 or "/" not in parts[1]:
            continue
        try:
            digest = hashlib.sha256(read_state_file(games / parts[1]).data).hexdigest()
        except RetrokitError:
            continue  # a shipped file missing or damaged here: it identifies nothing
        found[digest] = games / parts[1].split("/")[0]
    return found


def warm() -> None:
    """Read the digests of retrokit's and the wheel's shipped states now, once for every process forked from this one
    (an evaluation's fork server): they are the same for every state a process loads."""
    _shipped_states()
    _wheel_states()


@functools.cache
def _shipped_owner(folder: Path | None) -> Owner | None:
    """The game of retrokit's shipped game folder ``folder``."""
    return None if folder is None else Owner(folder.name, _game_sha1s(folder), "retrokit ships it")


@functools.cache
def _wheel_states() -> dict[str, tuple[str, ...]]:
    """The digest of the state in the wheel's ``.state`` files :data:`WHEEL_STATE_HASHES` lists, to the files' paths
    in the wheel's ``data`` folder; only files the installed wheel holds, by its ``RECORD``."""
    games = paths.repo_games_dir()
    try:
        listed = (games / WHEEL_STATE_HASHES).read_text(encoding="utf-8").splitlines() if games else []
    except (OSError, UnicodeDecodeError):
        listed = []
    installed = wheel_state_files()
    found: dict[str, tuple[str, ...]] = {}
    for line in listed:
        parts = line.split()
        if len(parts) == 3 and parts[2] in installed.get(parts[1], ()):
            found[parts[0]] = (*found.get(parts[0], ()), parts[2])
    return found


@functools.cache
def _wheel_owner(where: str | None) -> Owner | None:
    """The game of the wheel's state file at ``where`` in its ``data`` folder (``stable/<Folder>/<Name>.state``)."""
    root = paths.wheel_dir()
    if where is None or root is None or where.count("/") != 2:
        return None
    folder = root / "data" / where.rsplit("/", 1)[0]
    try:
        name = load_game(folder).name
    except RetrokitError:
        name = folder.name.removesuffix("-v0")
    return Owner(name, _game_sha1s(folder), "the stable-retro wheel ships it")


def load_state(game: Game, path: str | os.PathLike[str]) -> VettedState:
    """Read a ``.state`` file for ``game`` and return the state, once it is known to be safe to load.

    Raises:
        StateError: The file is not a valid state, is for another game's ROM, or crashes the core.
    """
    path = Path(path)
    state = read_state_file(path, game.system)
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
    """Note that retrokit wrote ``state`` (a core made it) for ``game``: reading it back from its file needs no probe,
    and it is refused for a game on another ROM, whatever file holds it."""
    rom_sha1 = cached_rom_sha1(rom if rom is not None else game.require_rom(), game.system)
    remember(state, rom_sha1)
    _record_owner(game, state, rom_sha1)


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

