"""Save-state files: gzip-compressed serialized core state, as stable-retro writes them.

A ``.state`` file is the bytes a libretro core's ``retro_serialize`` returns,
gzip-compressed. Whether a state fits a core (its size) is checked when it is
loaded into an emulator; this module checks that the file is a whole, valid
gzip stream.
"""

from __future__ import annotations

import gzip
import os
import zlib
from pathlib import Path

from retrokit.errors import FileConflictError, StateError
from retrokit.paths import atomic_write

GZIP_MAGIC = b"\x1f\x8b"


def decompress_state(blob: bytes, *, source: str = "the state") -> bytes:
    """Return the core state inside a gzip-compressed ``blob``.

    Args:
        blob: The contents of a ``.state`` file.
        source: What to call the blob in error messages (usually its path).

    Raises:
        StateError: ``blob`` is empty, not gzip, truncated or corrupt.
    """
    fix = "Record the state again, or copy it again from where it came from."
    if not blob:
        raise StateError(f"{source}: expected a gzip-compressed save state; found an empty file. {fix}")
    if blob[:2] != GZIP_MAGIC:
        raise StateError(
            f"{source}: expected a gzip-compressed save state (starting with bytes 1f 8b); "
            f"found {len(blob)} bytes starting with {blob[:8].hex(' ')}. If this is a raw "
            "core state, compress it with retrokit.data.states.write_state. " + fix
        )
    try:
        data = gzip.decompress(blob)
    except EOFError as exc:
        raise StateError(
            f"{source}: expected a complete gzip stream; found one that ends early after "
            f"{len(blob)} bytes: the file is truncated. {fix}"
        ) from exc
    except (gzip.BadGzipFile, zlib.error, OSError) as exc:
        raise StateError(f"{source}: expected a valid gzip stream; found a corrupt one ({exc}). {fix}") from exc
    if not data:
        raise StateError(f"{source}: expected a serialized core state; found a gzip stream of 0 bytes. {fix}")
    return data


def read_state(path: str | os.PathLike[str]) -> bytes:
    """Read a ``.state`` file and return the serialized core state.

    Raises:
        StateError: The file is missing, empty, not gzip, truncated or corrupt.
    """
    path = Path(path)
    try:
        blob = path.read_bytes()
    except OSError as exc:
        raise StateError(
            f"Expected a readable save state at {str(path)!r}; found an error: {exc.strerror or exc}."
        ) from exc
    return decompress_state(blob, source=str(path))


def compress_state(data: bytes) -> bytes:
    """Return ``data`` gzip-compressed the way ``.state`` files are (reproducibly: no timestamp)."""
    return gzip.compress(bytes(data), compresslevel=9, mtime=0)


def write_state(path: str | os.PathLike[str], data: bytes, *, overwrite: bool = False) -> Path:
    """Write a serialized core state to a ``.state`` file, gzip-compressed.

    The file is written to a temporary file and renamed into place. Writing the
    same state again is a no-op.

    Args:
        path: The destination file.
        data: The serialized core state (uncompressed).
        overwrite: Replace a different existing file.

    Returns:
        The path written.

    Raises:
        StateError: ``data`` is empty.
        FileConflictError: A different file exists at ``path`` and ``overwrite`` is false.
    """
    path = Path(path)
    data = bytes(data)
    if not data:
        raise StateError(f"{path}: expected a serialized core state to write; found 0 bytes.")
    if path.exists() and not overwrite:
        try:
            same = read_state(path) == data
        except StateError:
            same = False
        if same:
            return path
        raise _conflict(path)
    try:
        atomic_write(path, compress_state(data), overwrite=overwrite)
    except FileExistsError:
        raise _conflict(path) from None
    return path


def _conflict(path: Path) -> FileConflictError:
    return FileConflictError(
        f"Expected no file at {str(path)!r} or the same state; found a different file. "
        "Pass overwrite=True to replace it, or choose another name."
    )


# Genesis Plus GX (1.7.x) writes a 16-byte version string, then, for a Mega
# Drive, the 68000's 64 KiB of work RAM as the core holds it (host-order
# 16-bit words): so a state's fields can be read without the ROM or the core.
_GPGX_SIGNATURE = b"GENPLUS-GX"
_GPGX_RAM = slice(16, 16 + 0x10000)


def state_ram(data: bytes, system: str) -> bytes | None:
    """Return the system RAM inside a serialized core state, in the core's byte order, if its layout is known.

    Known: Genesis states of Genesis Plus GX. For others, ``None``: only a
    core can read them.

    Args:
        data: A serialized (uncompressed) core state.
        system: The system's name, e.g. ``"Genesis"``.
    """
    if system == "Genesis" and data[: len(_GPGX_SIGNATURE)] == _GPGX_SIGNATURE and len(data) >= _GPGX_RAM.stop:
        return bytes(data[_GPGX_RAM])
    return None


def state_format(data: bytes) -> str:
    """Return the printable signature a core put at the start of a state (e.g. ``"GENPLUS-GX 1.7.5"``), or ``""``."""
    head = data[:16].split(b"\0", 1)[0]
    return head.decode("ascii") if head and all(32 <= b < 127 for b in head) else ""
