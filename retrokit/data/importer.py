"""ROM import: find the ROMs of known games in folders and zip files, and copy them in.

Every regular file under the given paths is a candidate (devices, FIFOs and
sockets are skipped: they would block or never end), as are the members of zip
files (nested zips too, spooled to a temporary file) and the zip files themselves (FBNeo
arcade sets are zips). Each candidate is hashed by stable-retro's rules (see
:mod:`retrokit.data.roms`) and matched against the SHA-1s of every known game. A
match is written, through a temporary file, to ``<data>/roms/<Game>/rom.<ext>``
(``.smd`` dumps de-interleaved, as ``.md``). A different file already there is
never replaced unless asked. Folders whose names start with ``.`` (``.git``,
``.cache``) are not walked unless given by name.
"""

from __future__ import annotations

import os
import stat
import tempfile
import zipfile
import zlib
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, BinaryIO

from tqdm import tqdm

from retrokit import paths
from retrokit.data import roms
from retrokit.data.games import Game, list_games
from retrokit.errors import (
    FileConflictError,
    MissingExtraError,
    RetrokitError,
    RomError,
    UnknownNameError,
    did_you_mean,
)
from retrokit.host.systems import extension_of

ROM_PACKAGES: dict[str, tuple[str, str]] = {"ale-py": ("ale_py", "roms")}
"""Python packages that ship ROMs: the package's name on the index, its import name and its ROM folder
(``retrokit import --from ale-py``)."""
MAX_ZIP_DEPTH = 3
MAX_NESTED_ZIP_SIZE = 256 * 2**20
"""The largest zip inside a zip that is searched (spooled to a temporary file, never held in memory)."""
_CHUNK = 2**20
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
        differs: How the two files differ: their SHA-1s, or, when those are one (an NES ROM's leaves
            its iNES header out), their headers.
    """

    game: str
    source: str
    path: Path
    sha1: str
    existing_sha1: str
    differs: str = ""


@dataclass(frozen=True)
class UnmatchedFile:
    """A candidate whose SHA-1 matches no known game: perhaps a game nobody has integrated yet.

    Attributes:
        source: Where it was found (``archive.zip!member`` for zip members).
        sha1: Its SHA-1 (by stable-retro's rules, for its likely system's form).
        system: The system its header or extension suggests (``retrokit new`` takes it), or ``None``.
    """

    source: str
    sha1: str
    system: str | None


@dataclass
class ImportReport:
    """What :func:`import_roms` did.

    Attributes:
        data_dir: The data folder ROMs were imported into.
        imported: ROMs written (or replaced, with ``overwrite``).
        already_present: ROMs identical to the file already in place.
        conflicts: ROMs not written because a different file is in place.
        refused: Known games' ROMs not written because their header says the core cannot run them
            (what ``retrokit new`` refuses: an unknown mapper, sizes the file lacks), with the game and why.
        unmatched: Candidates whose SHA-1 matches no known game.
        skipped: Candidates not hashed, with the reason (unreadable, too big, bad zip).
        broken_games: Games whose data file could not be read, with the error.
        not_roms: Candidates that matched no game and look like no ROM (by extension, header and size).
    """

    data_dir: Path
    imported: list[ImportedRom] = field(default_factory=list)
    already_present: list[ImportedRom] = field(default_factory=list)
    conflicts: list[ImportConflict] = field(default_factory=list)
    refused: list[tuple[str, str, str]] = field(default_factory=list)
    unmatched: list[UnmatchedFile] = field(default_factory=list)
    skipped: list[tuple[str, str]] = field(default_factory=list)
    broken_games: list[tuple[str, str]] = field(default_factory=list)
    not_roms: list[str] = field(default_factory=list)


def package_roms(package: str) -> Path:
    """The ROM folder of an installed Python package that ships ROMs (``"ale-py"``).

    Raises:
        UnknownNameError: retrokit knows no such package.
        MissingExtraError: The package is not installed.
    """
    import importlib.util

    if package not in ROM_PACKAGES:
        raise UnknownNameError(
            f"Expected a package that ships ROMs ({', '.join(ROM_PACKAGES)}), got {package!r}."
            + did_you_mean(package, ROM_PACKAGES)
        )
    module, folder = ROM_PACKAGES[package]
    spec = importlib.util.find_spec(module)
    if spec is None or not spec.submodule_search_locations:
        raise MissingExtraError(f"Expected the package {package} to be installed; found it missing. Run: pip install {package}")
    return Path(next(iter(spec.submodule_search_locations))) / folder


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


def _read_capped(stream: BinaryIO, limit: int) -> bytes | None:
    """Read ``stream`` whole, or return ``None`` once it proves longer than ``limit`` bytes.

    Sizes that files and zip headers declare can lie (a device, a growing
    file, a forged header), so only the bytes really read count.
    """
    data = stream.read(limit + 1)
    return None if len(data) > limit else data


def _spool_member(archive: zipfile.ZipFile, info: zipfile.ZipInfo) -> IO[bytes] | None:
    """A nested zip member, copied to memory (small) or a temporary file, or ``None`` past the cap."""
    spool = tempfile.SpooledTemporaryFile(max_size=roms.MAX_FILE_SIZE)  # noqa: SIM115 - handed to the caller
    with archive.open(info) as member:
        copied = 0
        while chunk := member.read(_CHUNK):
            copied += len(chunk)
            if copied > MAX_NESTED_ZIP_SIZE:
                spool.close()
                return None
            spool.write(chunk)
    spool.seek(0)
    return spool


def _zip_candidates(label: str, opener: Callable[[], zipfile.ZipFile], report: ImportReport, depth: int) -> Iterator[_Candidate]:
    try:
        with opener() as archive:
            for info in sorted(archive.infolist(), key=lambda i: i.filename):
                if info.is_dir():
                    continue
                member = f"{label}!{info.filename}"
                ext = extension_of(info.filename)
                if _too_big(info.file_size) and ext != "zip":  # declared too big: no need to read it
                    report.skipped.append((member, _TOO_BIG))
                    continue
                try:
                    if ext == "zip" and depth < MAX_ZIP_DEPTH:
                        yield from _nested_zip_candidates(member, archive, info, report, depth)
                        continue
                    with archive.open(info) as stream:
                        data = _read_capped(stream, roms.MAX_FILE_SIZE)
                except (zipfile.BadZipFile, OSError, RuntimeError, NotImplementedError, EOFError, zlib.error) as exc:
                    report.skipped.append((member, f"unreadable zip member: {exc}"))
                    continue
                if data is None:
                    report.skipped.append((member, _TOO_BIG))
                    continue
                yield member, ext, lambda data=data: data
    except (zipfile.BadZipFile, OSError, EOFError) as exc:
        report.skipped.append((label, f"not a readable zip file: {exc}"))


def _nested_zip_candidates(
    member: str, archive: zipfile.ZipFile, info: zipfile.ZipInfo, report: ImportReport, depth: int
) -> Iterator[_Candidate]:
    """A zip inside a zip: itself (an arcade set) if small enough, and its members."""
    spool = _spool_member(archive, info)
    if spool is None:
        report.skipped.append((member, f"a zip larger than {MAX_NESTED_ZIP_SIZE // 2**20} MiB inside a zip"))
        return
    with spool:
        size = spool.seek(0, os.SEEK_END)
        spool.seek(0)
        if not _too_big(size):
            data = spool.read()
            spool.seek(0)
            yield member, "zip", lambda: data
        yield from _zip_candidates(member, lambda: zipfile.ZipFile(spool), report, depth + 1)


def _regular_file_size(path: Path, report: ImportReport) -> int | None:
    """The size of ``path`` if it is a regular file (after symlinks); else note why it is skipped."""
    try:
        info = path.stat()
    except OSError as exc:
        report.skipped.append((str(path), f"unreadable: {exc.strerror or exc}"))
        return None
    if not stat.S_ISREG(info.st_mode):  # a FIFO would block, a device (/dev/zero) never end
        report.skipped.append((str(path), "not a regular file (a device, FIFO or socket)"))
        return None
    return info.st_size


def _read_file(path: Path) -> bytes:
    with open(path, "rb") as f:
        data = _read_capped(f, roms.MAX_FILE_SIZE)
    if data is None:
        raise RomError(f"{path}: expected a ROM of at most {roms.MAX_ROM_SIZE // 2**20} MiB; found a file that grew past it.")
    return data


def _file_candidates(path: Path, report: ImportReport) -> Iterator[_Candidate]:
    label, ext = str(path), extension_of(path)
    size = _regular_file_size(path, report)
    if size is None:
        return
    if ext == "zip":
        if not _too_big(size):
            yield label, ext, lambda: _read_file(path)
        yield from _zip_candidates(label, lambda: zipfile.ZipFile(path), report, 1)
    elif _too_big(size):
        report.skipped.append((label, _TOO_BIG))
    else:
        yield label, ext, lambda: _read_file(path)


def _walk(path: Path, report: ImportReport) -> Iterator[_Candidate]:
    if path.is_dir():
        for root, dirs, files in os.walk(path):
            dirs[:] = sorted(d for d in dirs if not d.startswith("."))
            for name in sorted(files):
                yield from _file_candidates(Path(root) / name, report)
    elif path.exists():
        yield from _file_candidates(path, report)
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
                differs = roms.header_difference(game.system, existing, data) if existing_sha1 == sha1 else ""
                differs = differs or f"SHA-1 {existing_sha1} against {sha1}"
                report.conflicts.append(ImportConflict(game.name, source, target, sha1, existing_sha1, differs))
                continue
        try:
            paths.atomic_write(target, data, overwrite=overwrite)
        except FileConflictError:  # appeared meanwhile
            report.conflicts.append(ImportConflict(game.name, source, target, sha1, "(unknown)", "it appeared meanwhile"))
            continue
        report.imported.append(entry)


def import_roms(
    sources: Iterable[str | os.PathLike[str]],
    *,
    data_dir: str | os.PathLike[str] | None = None,
    overwrite: bool = False,
    games: Iterable[Game] | None = None,
    progress: bool = False,
) -> ImportReport:
    """Find the ROMs of known games under ``sources`` and copy them into the data folder.

    Args:
        sources: Files, folders (walked recursively) and zip files.
        data_dir: The data folder; by default :func:`retrokit.paths.data_dir`.
        overwrite: Replace a different ROM already imported for the same game.
        games: The games to match against; by default every known game.
        progress: Show a progress bar (on standard error) of the files searched.

    Returns:
        What was imported, already present, in conflict, unmatched and skipped.
    """
    report = ImportReport(Path(data_dir) if data_dir is not None else paths.data_dir())
    table, report.broken_games = known_hashes(games)
    candidates = (c for source in sources for c in _walk(Path(source), report))
    # closed on any error too, so an error prints on a line of its own
    with tqdm(candidates, desc="Searching", unit=" files", disable=not progress) as bar:
        for label, ext, read in bar:
            try:
                data, sha1 = roms.groom_rom(read(), ext)
            except (OSError, RomError) as exc:
                report.skipped.append((label, str(exc)))
                continue
            matches = table.get(sha1)
            if not matches:
                system, _ = roms.guess_system(data, label)
                if system is None and not roms.may_be_rom(label):  # a package's __init__.py, a readme.txt
                    report.not_roms.append(label)
                    continue
                report.unmatched.append(UnmatchedFile(label, sha1, system.name if system is not None else None))
                continue
            for game in matches:
                problem = roms.rom_problem(game.system, data)  # what `retrokit new` checks: the SHA-1 skips a header
                if problem:
                    report.refused.append((label, game.name, problem))
                else:
                    _store(game, label, data, sha1, report, overwrite)
    report.unmatched = _once_per_zip(report.unmatched, report.not_roms)
    return report


def _once_per_zip(unmatched: list[UnmatchedFile], not_roms: list[str]) -> list[UnmatchedFile]:
    """Leave out a zip whose members are listed or left out: a zip is searched whole (an arcade set) and by member.

    Listing both would show a zip holding no ROM twice; its members say more.
    """
    parents = set()
    for source in [entry.source for entry in unmatched] + not_roms:
        parts = source.split("!")
        parents.update("!".join(parts[:i]) for i in range(1, len(parts)))
    return [entry for entry in unmatched if entry.source not in parents]
