"""ROM identity: which system a file is for, and the SHA-1 that names it.

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

Systems and their extensions come from :mod:`retrokit.host.systems` (whose
descriptors a test keeps equal to the stable-retro wheel's ``cores/*.json``),
plus ``.smd`` for Genesis.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

from retrokit.errors import InvalidArgumentError, RomError, UnsupportedSystemError, did_you_mean
from retrokit.host.systems import all_systems, systems_by_extension

MAX_ROM_SIZE = 32 * 1024 * 1024
"""The largest ROM hashed or imported, as in stable-retro."""

NES_HEADER_SIZE = 16
SMD_HEADER_SIZE = 512
SMD_BLOCK_SIZE = 16 * 1024

MAX_FILE_SIZE = MAX_ROM_SIZE + SMD_HEADER_SIZE
"""The largest file read as a ROM: the largest ROM, as an ``.smd`` dump with its header."""


def system_extensions() -> dict[str, tuple[str, ...]]:
    """Return each system's ROM extensions (without dots), from :mod:`retrokit.host.systems`.

    The first extension of a system is the one its ROMs are stored under.

    Raises:
        DataFileError: ``systems.yaml`` is malformed.
    """
    return {name: system.extensions for name, system in all_systems().items()}


def extension_systems() -> dict[str, str]:
    """Return a map from ROM extension (without dot) to system name, aliases such as ``smd`` included."""
    return {ext: system.name for ext, system in systems_by_extension().items()}


def file_extension(filename: str | os.PathLike[str]) -> str:
    """Return a file name's extension, lowercase and without the dot (``""`` if none)."""
    return Path(filename).suffix.lower().lstrip(".")


def system_extension(system: str) -> str:
    """Return the extension (without dot) a ``system``'s ROMs are stored under.

    Raises:
        UnsupportedSystemError: ``system`` is not a known system.
    """
    exts = system_extensions().get(system)
    if not exts:
        known = sorted(system_extensions())
        raise UnsupportedSystemError(
            f"Expected one of the systems the stable-retro cores support ({', '.join(known)}); "
            f"found {system!r}. Fix the system name in the game's data file."
            + did_you_mean(system, known)
        )
    return exts[0]


def detect_system(filename: str | os.PathLike[str]) -> str:
    """Return the system a ROM file is for, from its extension.

    Raises:
        UnsupportedSystemError: The extension belongs to no known system.
    """
    ext = file_extension(filename)
    systems = extension_systems()
    if ext in systems:
        return systems[ext]
    known = sorted(systems)
    found = f"'.{ext}'" if ext else "no extension"
    raise UnsupportedSystemError(
        f"Expected a ROM file ending in one of {', '.join('.' + e for e in known)}; "
        f"found {found} in {os.fspath(filename)!r}. Rename the file with its system's extension."
        + did_you_mean(f".{ext}", [f".{e}" for e in known])
    )


def _rule(system_or_ext: str) -> str:
    """Return ``"nes"``, ``"smd"`` or ``""``: which grooming rule applies."""
    key = system_or_ext.lower().lstrip(".")
    if key in ("nes", "smd"):
        return key
    if system_or_ext in system_extensions() or key in extension_systems():
        return ""
    known = sorted(system_extensions()) + sorted(extension_systems())
    raise UnsupportedSystemError(
        f"Expected a system name or ROM extension; found {system_or_ext!r}."
        + did_you_mean(system_or_ext, known)
    )


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


def interleave_smd(data: bytes, header: bytes | None = None) -> bytes:
    """Convert a plain ``.md`` ROM to the ``.smd`` form (the inverse of :func:`deinterleave_smd`).

    Args:
        data: The ROM; its size should be a multiple of 16 KiB.
        header: The 512-byte SMD header; a minimal one by default.
    """
    if header is None:
        header = bytes([len(data) // SMD_BLOCK_SIZE & 0xFF, 3]) + bytes(6) + b"\xaa\xbb\x06" + bytes(501)
    out = bytearray()
    for start in range(0, len(data), SMD_BLOCK_SIZE):
        block = data[start : start + SMD_BLOCK_SIZE]
        out += block[1::2] + block[0::2]
    return bytes(header) + bytes(out)


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


def rom_sha1(source: bytes | str | os.PathLike[str], system_or_ext: str | None = None) -> str:
    """Return the SHA-1 that identifies a ROM, by stable-retro's rules.

    Args:
        source: The ROM's bytes, or a path to it.
        system_or_ext: A system name (``"Nes"``) or extension (``".nes"``, ``"smd"``)
            that says which rule applies; by default the path's extension.

    Raises:
        RomError: The file cannot be read, or is larger than 32 MiB.
        UnsupportedSystemError: ``system_or_ext`` is unknown.
    """
    if system_or_ext is None:
        system_or_ext = _source_ext(source)
    return groom_rom(_read(source), _rule(system_or_ext))[1]


def _source_ext(source: bytes | str | os.PathLike[str]) -> str:
    if isinstance(source, (bytes, bytearray, memoryview)):
        raise InvalidArgumentError(
            "Expected system_or_ext (a system name or a ROM extension) with raw ROM bytes; found None."
        )
    ext = file_extension(source)
    return ext if ext in extension_systems() else detect_system(source)
