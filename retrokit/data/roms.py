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


# Header signatures: (system, offset, bytes). A match names the system whatever the file's extension,
# so a Genesis ROM dumped as .bin (an extension N64 dumps use too) is still a Genesis ROM.
_SIGNATURES: tuple[tuple[str, int, bytes], ...] = (
    ("32x", 0x100, b"SEGA 32X"),
    ("Genesis", 0x100, b"SEGA"),
    ("Genesis", 0x101, b"SEGA"),  # " SEGA MEGA DRIVE": some headers start with a space
    ("Nes", 0, b"NES\x1a"),
    ("N64", 0, bytes.fromhex("80371240")),
    ("GbAdvance", 0xB2, b"\x96"),  # the fixed byte of every GBA header; checked with the logo below
)
_GB_LOGO = bytes.fromhex("CEED6666CC0D000B03730083000C000D0008111F8889000E")  # the start of the Nintendo logo at 0x104
_SMS_MARK = b"TMR SEGA"
_SMS_MARK_OFFSETS = (0x7FF0, 0x3FF0, 0x1FF0)
_GG_REGIONS = (5, 6, 7)  # the region nibble of a Game Gear header
_GBA_LOGO = bytes.fromhex("24FFAE51699AA2213D84820A")  # the start of the GBA's logo at 0x04


def header_system(data: bytes) -> str | None:
    """The system a ROM's header names, or ``None`` if no header retrokit knows is there.

    Args:
        data: The ROM, in its stored form (an ``.smd`` dump de-interleaved).
    """
    for system, offset, mark in _SIGNATURES:
        if system == "GbAdvance":
            if data[0x04 : 0x04 + len(_GBA_LOGO)] == _GBA_LOGO and data[offset : offset + 1] == mark:
                return system
            continue
        if data[offset : offset + len(mark)] == mark:
            return system
    if data[0x104 : 0x104 + len(_GB_LOGO)] == _GB_LOGO:
        return "GbColor" if len(data) > 0x143 and data[0x143] in (0x80, 0xC0) else "GameBoy"
    for offset in _SMS_MARK_OFFSETS:
        if data[offset : offset + len(_SMS_MARK)] == _SMS_MARK:
            region = data[offset + 0xF] >> 4 if len(data) > offset + 0xF else 0
            return "GameGear" if region in _GG_REGIONS else "Sms"
    return None


def guess_system(data: bytes, filename: str | os.PathLike[str]) -> tuple[System | None, str]:
    """The likely system of a file: from its header, else its extension; and how it was told.

    Returns:
        The system (``None`` if neither tells it) and ``"header"``, ``"extension"`` or ``""``.
    """
    named = header_system(data)
    if named is not None and named in all_systems():
        return get_system(named), "header"
    ext = extension_of(filename)
    known = systems_by_extension()
    if ext in known and ext != "bin":  # .bin is any dump: only a header tells what it is
        return known[ext], "extension"
    return None, ""
