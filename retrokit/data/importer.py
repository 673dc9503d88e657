"""ROM import: find the ROMs of known games in folders and zip files, and copy them in.

Every file under the given paths is a candidate, as are the members of zip
files (read in memory, nested zips too) and the zip files themselves (FBNeo
arcade sets are zips). Each candidate is hashed by stable-retro's rules (see
:mod:`retrokit.data.roms`) and matched against the SHA-1s of every known game. A
match is written, through a temporary file, to ``<data>/roms/<Game>/rom.<ext>``
(``.smd`` dumps de-interleaved, as ``.md``). A different file already there is
never replaced unless asked. Folders whose names start with ``.`` (``.git``,
``.cache``) are not walked unless given by name.
"""

from __future__ import annotations

import io
import os
import zipfile
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

from retrokit import paths
from retrokit.data import roms
from retrokit.data.games import Game, list_games
from retrokit.errors import RetrokitError, RomError
from retrokit.host.systems import extension_of

MAX_ZIP_DEPTH = 3
_TOO_BIG = f"larger than {roms.MAX_ROM_SIZE // 2**20} MiB"


@dataclass(frozen=True)
class ImportedRom:
    """One ROM matched to one game.

    Attributes:
        game: The game's name.
        source: Where the ROM was found (``archive.zip!member`` for zip members).
        path: Where it is stored.
        sha1: Its SHA-1 (by stable-retro's rules).
    """

    game: str
    source: str
    path: Path
    sha1: str


@dataclass(frozen=True)
class ImportConflict:
    """A ROM not written because a different file is in its place.

    Attributes:
        game: The game's name.
        source: Where the new ROM was found.
        path: The existing file, left as it was.
        sha1: The new ROM's SHA-1.
        existing_sha1: The existing file's SHA-1 (by the same rules).
    """

    game: str
    source: str
    path: Path
    sha1: str
    existing_sha1: str


@dataclass
class ImportReport:
    """What :func:`import_roms` did.

    Attributes:
        data_dir: The data folder ROMs were imported into.
        imported: ROMs written (or replaced, with ``overwrite``).
        already_present: ROMs identical to the file already in place.
        conflicts: ROMs not written because a different file is in place.
        unmatched: Candidates whose SHA-1 matches no known game.
        skipped: Candidates not hashed, with the reason (unreadable, too big, bad zip).
        broken_games: Games whose data file could not be read, with the error.
    """

    data_dir: Path
    imported: list[ImportedRom] = field(default_factory=list)
    already_present: list[ImportedRom] = field(default_factory=list)
    conflicts: list[ImportConflict] = field(default_factory=list)
    unmatched: list[str] = field(default_factory=list)
    skipped: list[tuple[str, str]] = field(default_factory=list)
    broken_games: list[tuple[str, str]] = field(default_factory=list)


def known_hashes(games: Iterable[Game] | None = None) -> tuple[dict[str, list[Game]], list[tuple[str, str]]]:
    """Map each known ROM SHA-1 to the games that accept it.

    Returns:
        The map, and the games whose data file could not be read (name, error).
    """
    table: dict[str, list[Game]] = {}
    broken: list[tuple[str, str]] = []
    for game in list_games() if games is None else games:
        try:
            sha1s = game.sha1s
        except RetrokitError as exc:
            broken.append((game.name, str(exc)))
            continue
        for sha1 in sha1s:
            table.setdefault(sha1, []).append(game)
    return table, broken


# A candidate: its description, its extension, and a function that reads it.
_Candidate = tuple[str, str, Callable[[], bytes]]


def _too_big(size: int) -> bool:
    return size > roms.MAX_FILE_SIZE


def _zip_candidates(label: str, opener: Callable[[], zipfile.ZipFile], report: ImportReport, depth: int) -> Iterator[_Candidate]:
    try:
        with opener() as archive:
            for info in sorted(archive.infolist(), key=lambda i: i.filename):
                if info.is_dir():
                    continue
                member = f"{label}!{info.filename}"
                ext = extension_of(info.filename)
                if _too_big(info.file_size) and ext != "zip":
                    report.skipped.append((member, _TOO_BIG))
                    continue
                try:
                    data = archive.read(info)
                except (zipfile.BadZipFile, OSError, RuntimeError, NotImplementedError) as exc:
                    report.skipped.append((member, f"unreadable zip member: {exc}"))
                    continue
                yield from _blob_candidates(member, ext, data, report, depth + 1)
    except (zipfile.BadZipFile, OSError) as exc:
        report.skipped.append((label, f"not a readable zip file: {exc}"))


def _blob_candidates(label: str, ext: str, data: bytes, report: ImportReport, depth: int) -> Iterator[_Candidate]:
    if ext == "zip" and depth <= MAX_ZIP_DEPTH:
        if not _too_big(len(data)):
            yield label, ext, lambda: data
        yield from _zip_candidates(label, lambda: zipfile.ZipFile(io.BytesIO(data)), report, depth)
    elif not _too_big(len(data)):
        yield label, ext, lambda: data


def _file_candidates(path: Path, report: ImportReport) -> Iterator[_Candidate]:
    label, ext = str(path), extension_of(path)
    try:
        size = path.stat().st_size
    except OSError as exc:
        report.skipped.append((label, f"unreadable: {exc.strerror or exc}"))
        return
    if ext == "zip":
        if not _too_big(size):
            yield label, ext, path.read_bytes
        yield from _zip_candidates(label, lambda: zipfile.ZipFile(path), report, 1)
    elif _too_big(size):
        report.skipped.append((label, _TOO_BIG))
    else:
        yield label, ext, path.read_bytes


def _walk(path: Path, report: ImportReport) -> Iterator[_Candidate]:
    if path.is_file():
        yield from _file_candidates(path, report)
    elif path.is_dir():
        for root, dirs, files in os.walk(path):
            dirs[:] = sorted(d for d in dirs if not d.startswith("."))
            for name in sorted(files):
                yield from _file_candidates(Path(root) / name, report)
    else:
        report.skipped.append((str(path), "no such file or folder"))


def _store(game: Game, source: str, data: bytes, sha1: str, report: ImportReport, overwrite: bool) -> None:
    dest = game.imported_rom_path(report.data_dir)
    targets = [dest]
    if game.info.original_rom_name:  # FBNeo cores load the set by its original name
        targets.append(dest.with_name(Path(game.info.original_rom_name).name))
    for target in targets:
        entry = ImportedRom(game.name, source, target, sha1)
        if target.is_file():
            existing = target.read_bytes()
            if existing == data:
                report.already_present.append(entry)
                continue
            if not overwrite:
                existing_sha1 = roms.rom_sha1(existing, game.system)
                report.conflicts.append(ImportConflict(game.name, source, target, sha1, existing_sha1))
                continue
        try:
            paths.atomic_write(target, data, overwrite=overwrite)
        except FileExistsError:  # appeared meanwhile
            report.conflicts.append(ImportConflict(game.name, source, target, sha1, "(unknown)"))
            continue
        report.imported.append(entry)


def import_roms(
    sources: Iterable[str | os.PathLike[str]],
    *,
    data_dir: str | os.PathLike[str] | None = None,
    overwrite: bool = False,
    games: Iterable[Game] | None = None,
) -> ImportReport:
    """Find the ROMs of known games under ``sources`` and copy them into the data folder.

    Args:
        sources: Files, folders (walked recursively) and zip files.
        data_dir: The data folder; by default :func:`retrokit.paths.data_dir`.
        overwrite: Replace a different ROM already imported for the same game.
        games: The games to match against; by default every known game.

    Returns:
        What was imported, already present, in conflict, unmatched and skipped.
    """
    report = ImportReport(Path(data_dir) if data_dir is not None else paths.data_dir())
    table, report.broken_games = known_hashes(games)
    for label, ext, read in (c for source in sources for c in _walk(Path(source), report)):
        try:
            data, sha1 = roms.groom_rom(read(), ext)
        except (OSError, RomError) as exc:
            report.skipped.append((label, str(exc)))
            continue
        matches = table.get(sha1)
        if not matches:
            report.unmatched.append(label)
            continue
        for game in matches:
            _store(game, label, data, sha1, report, overwrite)
    return report
