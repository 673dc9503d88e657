"""ROM identity: the SHA-1 that names a ROM, and the form a ROM is stored in.

The rules are stable-retro's (``retro.data.groom_rom``), so every ``rom.sha``
of the Gym Retro and stable-retro integrations matches:

- ``.nes`` files: the 16-byte iNES header is left out of the hash (the file is
  stored whole, header included, because the core needs it).
- ``.smd`` files (Super Magic Drive dumps of Genesis games): a 512-byte header,
  then 16 KiB blocks whose first 8 KiB hold the odd bytes and the last 8 KiB
  the even bytes. They are de-interleaved into the plain ``.md`` form, which is
  what is hashed and stored. A file without the SMD signature (``"EA"`` at
  offsets 0x80 of the body, the interleaved ``"SEGA"``) is taken as it is.
- Every other file is hashed whole, up to 32 MiB (the largest game supported).

Which system a file extension belongs to is :mod:`retrokit.host.systems`'
business; this module hashes and grooms, and reads the headers that name a
ROM's system (:func:`header_system`), for ROMs no game knows yet.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

from retrokit.errors import InvalidArgumentError, RomError
from retrokit.host.systems import (
    DetectRule,
    System,
    all_systems,
    extension_of,
    get_system,
    system_for_extension,
    systems_by_extension,
)

MAX_ROM_SIZE = 32 * 1024 * 1024
"""The largest ROM hashed or imported, as in stable-retro."""

NES_HEADER_SIZE = 16
SMD_HEADER_SIZE = 512
SMD_BLOCK_SIZE = 16 * 1024

MAX_FILE_SIZE = MAX_ROM_SIZE + SMD_HEADER_SIZE
"""The largest file read as a ROM: the largest ROM, as an ``.smd`` dump with its header."""


def is_smd(data: bytes) -> bool:
    """Return whether ``data`` looks like an interleaved Super Magic Drive dump."""
    body = data[SMD_HEADER_SIZE:]
    return body[0x80:0x82] == b"EA"


def deinterleave_smd(data: bytes) -> bytes:
    """Convert a Super Magic Drive (``.smd``) dump to the plain ``.md`` form.

    Data without the SMD signature is returned unchanged, as stable-retro does.
    """
    if not is_smd(data):
        return data
    body = memoryview(data)[SMD_HEADER_SIZE:]
    out = bytearray(len(body))
    for start in range(0, len(body), SMD_BLOCK_SIZE):
        block = body[start : start + SMD_BLOCK_SIZE]
        n = len(block) // 2
        # A block's first half holds the odd bytes, its second half the even ones.
        out[start : start + 2 * n : 2] = block[n : 2 * n]
        out[start + 1 : start + 2 * n : 2] = block[:n]
        out[start + 2 * n : start + len(block)] = block[2 * n :]
    return bytes(out)


def _read(source: bytes | str | os.PathLike[str]) -> bytes:
    if isinstance(source, (bytes, bytearray, memoryview)):
        return bytes(source)
    path = Path(source)
    try:
        size = path.stat().st_size
        if size > MAX_FILE_SIZE:
            raise RomError(
                f"Expected a ROM of at most {MAX_ROM_SIZE // 2**20} MiB; found {size} bytes in "
                f"{str(path)!r}. This file is not a ROM retrokit supports."
            )
        return path.read_bytes()
    except OSError as exc:
        raise RomError(f"Expected a readable ROM file at {str(path)!r}; found an error: {exc}.") from exc


def groom_rom(data: bytes, ext: str) -> tuple[bytes, str]:
    """Return a ROM file's stored form and its SHA-1, given the file's extension.

    Any extension is accepted: those without a rule (``nes``, ``smd``) are
    hashed whole, as stable-retro does.

    Raises:
        RomError: The ROM is larger than 32 MiB.
    """
    ext = ext.lower().lstrip(".")
    if ext == "smd":
        data = deinterleave_smd(data)
    if len(data) > MAX_ROM_SIZE:
        raise RomError(
            f"Expected a ROM of at most {MAX_ROM_SIZE // 2**20} MiB; found {len(data)} bytes. "
            "This is not a ROM retrokit supports."
        )
    body = memoryview(data)[NES_HEADER_SIZE:] if ext == "nes" else memoryview(data)
    return bytes(data), hashlib.sha1(body).hexdigest()


def rom_sha1(source: bytes | str | os.PathLike[str], form: System | str | None = None) -> str:
    """Return the SHA-1 that identifies a ROM, by stable-retro's rules.

    Args:
        source: The ROM's bytes, or a path to it.
        form: Which rule applies: a system (or its name, ``"Nes"``), whose
            stored ROMs this is, or a file extension (``".nes"``, ``"smd"``:
            an SMD dump is de-interleaved first); by default the path's extension.

    Raises:
        RomError: The file cannot be read, or is larger than 32 MiB.
        UnsupportedSystemError: ``form`` names no system and no ROM extension.
    """
    if form is None:
        if isinstance(source, (bytes, bytearray, memoryview)):
            raise InvalidArgumentError(
                "Expected a form (a system or a ROM extension) with raw ROM bytes; found None. Pass e.g. 'Genesis'."
            )
        form = extension_of(source)
    return groom_rom(_read(source), _rule(form))[1]


def _rule(form: System | str) -> str:
    """The extension whose grooming rule applies to a ROM of this form."""
    if isinstance(form, System):
        return form.extensions[0]
    ext = form.lower().lstrip(".")
    if form.startswith(".") or ext in systems_by_extension():
        system_for_extension(ext)  # an unknown extension raises, with a suggestion
        return ext
    return get_system(form).extensions[0]


ROM_EXTENSIONS = frozenset({"bin", "rom", "zip"})
"""Extensions a ROM dump may have beyond the systems' own."""


def may_be_rom(filename: str | os.PathLike[str]) -> bool:
    """Whether a file's extension is one a ROM dump has (a system's, ``.bin``, ``.rom``, ``.zip``): not ``.py``, ``.txt``."""
    ext = extension_of(filename)
    return ext in ROM_EXTENSIONS or ext in systems_by_extension()


def _rule_score(rule: DetectRule, data: bytes) -> int:
    """How many bytes of ``data`` a header rule compared and found (0: it does not hold)."""
    size = 4 if rule.complement else len(rule.mark)
    for offset in rule.at:
        found = data[offset : offset + size]
        if rule.complement:
            if len(found) < size or int.from_bytes(found[:2], "little") ^ int.from_bytes(found[2:], "little") != 0xFFFF:
                continue
        elif found != rule.mark:
            continue
        if rule.byte_at is None:
            return size
        where = offset + rule.byte_at
        if 0 <= where < len(data) and data[where] >> rule.byte_shift in rule.byte_in:
            return size + 1
    return 0


def header_system(data: bytes) -> str | None:
    """The system a ROM's header names (``detect:`` in systems.yaml), or ``None`` if no header rule holds.

    Where several hold, the one that compared the most bytes names it (a 32X
    ROM's header also says ``SEGA`` where a Genesis ROM's does).

    Args:
        data: The ROM, in its stored form (an ``.smd`` dump de-interleaved).
    """
    best, named = 0, None
    for system in all_systems().values():
        for rule in system.detect:
            score = _rule_score(rule, data) if rule.at else 0
            if score > best:
                best, named = score, system.name
    return named


def size_system(size: int, filename: str | os.PathLike[str]) -> System | None:
    """The system whose header-less ROMs have this file size and extension (an Atari 2600 ``.bin``), or ``None``."""
    ext = extension_of(filename)
    for system in all_systems().values():
        for rule in system.detect:
            if size in rule.sizes and ext in rule.extensions:
                return system
    return None


INES_PRG_UNIT = 16 * 1024
INES_CHR_UNIT = 8 * 1024
INES_TRAINER = 512


def _ines_header(data: bytes) -> dict[str, int]:
    """What an iNES header says (the file is at least its 16 bytes): sizes in units, the mapper, a trainer."""
    prg, chr_, flags6, flags7 = data[4], data[5], data[6], data[7]
    mapper = (flags6 >> 4) | (flags7 & 0xF0)
    if flags7 & 0x0C == 0x08:  # NES 2.0: 4 more bits of mapper in byte 8 (numbers past 255 are left to the core)
        mapper |= (data[8] & 0x0F) << 8
    return {"program ROM (16 KiB units)": prg, "character ROM (8 KiB units)": chr_, "mapper": mapper,
            "trainer": int(bool(flags6 & 0x04)), "mirroring and battery flags": flags6 & 0x0B}


def _ines_problem(system: System, data: bytes) -> str:
    """What is wrong with an iNES ROM for ``system``'s core: too short for its header's sizes, or an unknown mapper."""
    if len(data) < NES_HEADER_SIZE:
        return f"it is {len(data)} bytes, shorter than the {NES_HEADER_SIZE}-byte iNES header"
    header = _ines_header(data)
    prg, chr_ = header["program ROM (16 KiB units)"], header["character ROM (8 KiB units)"]
    need = NES_HEADER_SIZE + INES_TRAINER * header["trainer"] + prg * INES_PRG_UNIT + chr_ * INES_CHR_UNIT
    if prg == 0:
        return "its iNES header gives it no program ROM (byte 4 is 0)"
    if len(data) < need:
        return (f"it is truncated: its iNES header gives {prg} x 16 KiB of program ROM and {chr_} x 8 KiB of "
                f"character ROM, {need} bytes with the header, and the file has {len(data)}")
    if header["mapper"] in system.missing_mappers:
        return f"its iNES mapper {header['mapper']} is one the {system.core} core cannot run (it has no such board)"
    return ""


def header_difference(system: System, first: bytes, second: bytes) -> str:
    """How the headers of two ROMs of ``system`` differ, where its format has one (``""``: none, or the same).

    Two files with one SHA-1 (which leaves an iNES header out) differ only there: this says how.
    """
    if system.rom_format != "ines" or min(len(first), len(second)) < NES_HEADER_SIZE:
        return ""
    one, two = _ines_header(first), _ines_header(second)
    changed = [f"{key} {one[key]} against {two[key]}" for key in one if one[key] != two[key]]
    if not changed and first[:NES_HEADER_SIZE] != second[:NES_HEADER_SIZE]:
        changed = [f"header bytes {first[:NES_HEADER_SIZE].hex()} against {second[:NES_HEADER_SIZE].hex()}"]
    return "their iNES headers differ: " + ", ".join(changed) if changed else ""


_FORMATS = {"ines": _ines_problem}


def rom_problem(system: System, data: bytes) -> str:
    """Why ``data`` cannot be a ROM ``system``'s core runs, by what its header says (``""``: nothing known).

    Only systems whose descriptor names a ``rom.format`` are checked (the NES's iNES header).
    """
    check = _FORMATS.get(system.rom_format)
    return check(system, data) if check else ""


def guess_system(data: bytes, filename: str | os.PathLike[str]) -> tuple[System | None, str]:
    """The likely system of a file: from its header, else its size, else its extension; and how it was told.

    The extension wins over a header where its system's ROMs carry that header (``extension_wins_over``:
    a ``.32x`` file's Genesis header, a ``.gb`` file's header saying it also runs on the Color).

    This is the one place a ROM's system is told from the file (retrokit new, retrokit import).

    Returns:
        The system (``None`` if nothing tells it) and ``"header"``, ``"size"``, ``"extension"`` or ``""``.
    """
    named = header_system(data)
    ext = extension_of(filename)
    known = systems_by_extension()
    if named is not None:
        if ext in known and named in known[ext].extension_wins_over:  # a .32x file with a Genesis header
            return known[ext], "extension"
        return get_system(named), "header"
    by_size = size_system(len(data), filename)
    if by_size is not None:
        return by_size, "size"
    if ext in known and ext != "bin":  # .bin is any dump: only a header or a size tells what it is
        return known[ext], "extension"
    return None, ""
