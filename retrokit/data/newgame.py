"""A new game from a bare ROM: telling its system, and making its folder in the user's games.

``retrokit new ROM --name NAME-SYSTEM`` is the first step of integrating a
game nobody has integrated: the ROM's system is told from its header (a
Genesis cartridge says ``SEGA`` at 0x100 whatever the file is called), its size
(an Atari 2600 cartridge has no header), its file extension, or the name's
system suffix (:func:`retrokit.data.roms.guess_system`); a folder ``<data>/games/NAME-SYSTEM/`` is made in
the user's games folder (:func:`retrokit.paths.user_games_dir`, searched by
every command) with a ``game.yaml`` that holds the system and the ROM's SHA-1
and no fields yet; and the ROM is imported into ``<data>/roms/NAME-SYSTEM/``
as ``retrokit import`` would.
"""

from __future__ import annotations

import json
import os
import re
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from retrokit import paths
from retrokit.data import roms
from retrokit.data.games import Game, list_games, normalize_name
from retrokit.errors import (
    FileConflictError,
    InvalidArgumentError,
    RomError,
    did_you_mean,
    shell_word,
)
from retrokit.host.systems import System, all_systems, extension_of, get_system

__all__ = ["NewGame", "check_new_name", "new_game", "read_rom"]

_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_]*-[A-Za-z0-9]+$")

def check_new_name(name: str, system: System) -> str:
    """Return ``name`` if it is a valid name for a new game of ``system``: ``<Name>-<System>``, unused.

    Raises:
        InvalidArgumentError: The name is not ``<Name>-<System>`` with ``system``'s name.
        FileConflictError: A game of that name (whatever its case) is known already.
    """
    example = f"{re.sub(r'[^A-Za-z0-9_]', '', name.rsplit('-', 1)[0]) or 'MyGame'}-{system.name}"
    if not isinstance(name, str) or not _NAME.match(name) or normalize_name(name) != name:
        raise InvalidArgumentError(
            f"Expected the game's name as <Name>-<System>, letters, digits and underscores then the system "
            f"(e.g. {example}); found {name!r}. Pass --name {example}."
        )
    suffix = name.rsplit("-", 1)[1]
    if suffix != system.name:
        hint = did_you_mean(suffix, all_systems()) if suffix not in all_systems() else ""
        raise InvalidArgumentError(
            f"Expected the name to end with the ROM's system, -{system.name}; found -{suffix} in {name!r}. "
            f"Pass --name {example}" + (", or --system to say the ROM's system." if suffix in all_systems() else ".")
            + hint
        )
    known = [g.name for g in list_games()]
    same = [k for k in known if k.lower() == name.lower()]
    if same:
        raise FileConflictError(
            f"Expected a name no game has; found {same[0]!r}, a known game. Choose another name (retrokit games "
            "lists the taken ones), or work on that game."
        )
    return name


@dataclass(frozen=True)
class NewGame:
    """What :func:`new_game` made.

    Attributes:
        game: The new game (its only folder is the new one).
        folder: Its folder in the user's games, holding ``game.yaml``.
        rom: Where its ROM was imported.
        sha1: The ROM's SHA-1 (by stable-retro's rules).
        told_by: How the system was told: ``"header"``, ``"size"``, ``"extension"``, ``"name"`` or ``"--system"``.
    """

    game: Game
    folder: Path
    rom: Path
    sha1: str
    told_by: str


def read_rom(path: str | os.PathLike[str]) -> bytes:
    """Read a ROM file: a regular file, not empty, at most :data:`retrokit.data.roms.MAX_FILE_SIZE` bytes.

    A file that reads otherwise than its size says (``/proc/self/environ``
    says 0 bytes, then gives the process's environment) is no ROM either.

    Raises:
        FileSystemError: The path is missing or not a regular file.
        RomError: The file is empty or too big, or its contents are not the size it says.
    """
    path = paths.require_regular_file(path, "a ROM file")
    size = path.stat().st_size
    if size > roms.MAX_FILE_SIZE:
        raise RomError(
            f"Expected a ROM of at most {roms.MAX_ROM_SIZE // 2**20} MiB; found {size} bytes in "
            f"{str(path)!r}. This file is not a ROM retrokit supports."
        )
    with open(path, "rb") as f:
        data = f.read(roms.MAX_FILE_SIZE + 1)
    if not data:
        raise RomError(f"Expected a ROM in {str(path)!r}; found an empty file.")
    if len(data) != size:
        raise RomError(
            f"Expected a ROM file of the {size} bytes its size says; found {len(data)} bytes in {str(path)!r} "
            "(a file that changed as it was read, or not a file on a disk). Copy the ROM to a file and pass that."
        )
    return data


def new_game(
    rom: str | os.PathLike[str],
    name: str,
    *,
    system: str | None = None,
    data_dir: str | os.PathLike[str] | None = None,
) -> NewGame:
    """Make a new game from a ROM in the user's games folder, and import its ROM.

    Args:
        rom: The ROM file.
        name: The new game's name, ``<Name>-<System>`` (e.g. ``"Runner-Genesis"``).
        system: The ROM's system, when neither its header nor its extension tells it.
        data_dir: The data folder; by default :func:`retrokit.paths.data_dir`.

    Returns:
        The game, its folder, its imported ROM and SHA-1.

    Raises:
        RomError: The file is not a ROM of a system retrokit knows (or is empty, or too big).
        InvalidArgumentError: ``name`` is not ``<Name>-<System>`` for the ROM's system.
        FileConflictError: A game of that name is known, or its folder exists; or the ROM is a known game's.
        UnsupportedSystemError: ``system`` names no system.
    """
    from retrokit.data.importer import import_roms, known_hashes

    data = read_rom(rom)
    told_by = "--system"
    if system is not None:
        chosen = get_system(system)
    else:
        chosen, told_by = roms.guess_system(roms.deinterleave_smd(data) if extension_of(rom) == "smd" else data, rom)
        suffix = name.rsplit("-", 1)[-1] if isinstance(name, str) else ""
        if chosen is None and suffix in all_systems() and roms.may_be_rom(rom):  # the name says it: Galaxian-Atari2600
            chosen, told_by = get_system(suffix), "name"
        if chosen is None:
            raise RomError(
                f"Expected a ROM whose header, size or file extension tells its system; found none in {str(rom)!r} "
                f"({len(data)} bytes, extension {'.' + extension_of(rom) if extension_of(rom) else 'none'}, no "
                f"known header). If it is a ROM, end --name with its system (as in Galaxian-Atari2600), "
                f"or pass --system {'|'.join(all_systems())}."
            )
    problem = roms.rom_problem(chosen, data)
    if problem:
        raise RomError(f"Expected a {chosen.name} ROM the {chosen.core} core runs; found that {str(rom)!r}: {problem}.")
    sizes = sorted(size for rule in chosen.detect for size in rule.sizes)
    if sizes and not sizes[0] <= len(data) <= sizes[-1]:  # a system whose ROMs have no header: only sizes tell
        raise RomError(
            f"Expected a ROM of {sizes[0]} to {sizes[-1]} bytes for {chosen.name}; found {len(data)} bytes in "
            f"{str(rom)!r}. It is no {chosen.name} cartridge: check the file."
        )
    _, sha1 = roms.groom_rom(data, extension_of(rom) if extension_of(rom) == "smd" else chosen.extensions[0])
    check_new_name(name, chosen)
    owners = known_hashes()[0].get(sha1, [])
    if owners:
        raise FileConflictError(
            f"Expected a ROM no game knows; found that {str(rom)!r} (SHA-1 {sha1}) is the ROM of "
            f"{', '.join(g.name for g in owners)}. Import it with: retrokit import {shell_word(rom)}"
        )
    folder = paths.data_path("games", name, data=data_dir)  # never through a planted link
    if folder.exists():
        raise FileConflictError(
            f"Expected no folder at {folder} for the new game; found one. Move it away, or pick another name."
        )
    paths.atomic_write(folder / "game.yaml", game_yaml(name, chosen, sha1, Path(rom).name).encode(),
                       hint="Pick another name, or work on that game.")
    game = Game(name, (folder,))
    try:  # a game without its ROM is half made: nothing is left of it
        report = import_roms([rom], data_dir=data_dir, games=[game])
        stored = [r.path for r in (*report.imported, *report.already_present)]
        if not stored:
            raise RomError(_not_imported(rom, chosen, sha1, game.imported_rom_path(data_dir), report))
    except BaseException:
        shutil.rmtree(folder, ignore_errors=True)
        raise
    return NewGame(game, folder, stored[0], sha1, told_by)


def _not_imported(rom: str | os.PathLike[str], chosen: System, sha1: str, target: Path, report: Any) -> str:
    """Why ``new`` could not import the ROM it made a game for (the game's folder is removed)."""
    if report.conflicts:
        found = "; ".join(f"{c.path}: {c.differs}" for c in report.conflicts)
        return (
            f"Expected to import the ROM into {target}; found another file there ({found}). Nothing was made. "
            f"Move that file away, then run `retrokit new` again."
        )
    ext = extension_of(rom)
    return (
        f"Expected {str(rom)!r} to import as a {chosen.name} ROM (SHA-1 {sha1}); found that its file, read as the "
        f".{ext or '(no extension)'} file it is, gives another SHA-1, so it is not a {chosen.name} ROM. Nothing was "
        "made. Leave out --system (its header or extension tells the system), or pass the ROM of that system."
    )




def game_yaml(name: str, system: System, sha1: str, source: str) -> str:
    """The ``game.yaml`` of a new game: its system and ROM, and room for the fields ramsearch finds."""
    return (
        f"# {name}: made by `retrokit new`. Fields come from ramsearch\n"
        "# (retrokit ramsearch save NAME ADDRESS TYPE), states from recipes or\n"
        "# ramsearch savestate; the format: retrokit docs integrate.\n"
        f"system: {system.name}\n"
        f"title: {name.rsplit('-', 1)[0]}\n"
        "roms:\n"
        f"  - sha1: {sha1}\n"
        f"    label: {json.dumps(source)}\n"  # a JSON string is a YAML one, whatever the file name holds
    )

