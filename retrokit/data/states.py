"""Save-state files: gzip-compressed serialized core state, as stable-retro writes them.

A ``.state`` file is the bytes a libretro core's ``retro_serialize`` returns,
gzip-compressed. Whether a state fits a core (its size) is checked when it is
loaded into an emulator; this module checks that the file is a whole, valid
gzip stream, no larger than any core's state once inflated.

States retrokit writes carry a :class:`StateRecord` (the game, its ROM's SHA-1
and the state's SHA-256) in the gzip header's extra field (RFC 1952, subfield
``RK``), which every gzip reader, stable-retro's included, skips: the file
stays an ordinary ``.state``.
"""

from __future__ import annotations

import gzip
import hashlib
import io
import json
import os
import zlib
from dataclasses import dataclass
from pathlib import Path

from retrokit.errors import FileConflictError, FileSystemError, StateError
from retrokit.host.systems import System, get_system, largest_state
from retrokit.paths import REPLACE_HINT, atomic_write, read_regular_file

GZIP_MAGIC = b"\x1f\x8b"
MAX_STATE_SIZE = largest_state()
"""The largest core state read for no known system: the largest any core writes (``state_max`` in systems.yaml:
parallel_n64's 16,789,312 bytes, mednafen_saturn's up to 22 MiB; Genesis Plus GX's is 1 MiB)."""
MAX_STATE_FILE_SIZE = MAX_STATE_SIZE + 2**20
"""The largest ``.state`` file read: a state that deflate could not shrink, with room for gzip's framing."""


def _inflate(blob: bytes, max_size: int) -> bytes | None:
    """Inflate a gzip stream, or return ``None`` as soon as it would pass ``max_size`` bytes.

    A gzip bomb (1 MiB inflating to 1 GiB) is refused after ``max_size`` bytes,
    never inflated whole. Raises what :func:`gzip.decompress` raises for a bad stream.
    """
    with gzip.GzipFile(fileobj=io.BytesIO(blob)) as stream:
        data = stream.read(max_size + 1)
    return None if len(data) > max_size else data


def decompress_state(
    blob: bytes, *, source: str = "the state", max_size: int | None = None, system: str | System | None = None
) -> bytes:
    """Return the core state inside a gzip-compressed ``blob``.

    Args:
        blob: The contents of a ``.state`` file.
        source: What to call the blob in error messages (usually its path).
        max_size: Refuse a state that inflates past this many bytes (by default
            ``system``'s ``state_max``, or :data:`MAX_STATE_SIZE` for no system).
        system: The system whose core the state is for, when it is known.

    Raises:
        StateError: ``blob`` is empty, not gzip, truncated, corrupt or too large.
    """
    known = get_system(system) if system is not None else None
    if max_size is None:
        max_size = known.state_max if known is not None else MAX_STATE_SIZE
    whose = f"no state of the {known.core} core" if known is not None else "no core's state"
    of = f" of {known.name}" if known is not None else ""
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
        data = _inflate(blob, max_size)
    except EOFError as exc:
        raise StateError(
            f"{source}: expected a complete gzip stream; found one that ends early after "
            f"{len(blob)} bytes: the file is truncated. {fix}"
        ) from exc
    except (gzip.BadGzipFile, zlib.error, OSError) as exc:
        raise StateError(f"{source}: expected a valid gzip stream; found a corrupt one ({exc}). {fix}") from exc
    if data is None:
        raise StateError(
            f"{source}: expected a save state of at most {max_size:,} bytes once inflated ({whose} is larger); "
            f"found a gzip stream of {len(blob):,} bytes that inflates past that: it is not a save state{of}."
        )
    if not data:
        raise StateError(f"{source}: expected a serialized core state; found a gzip stream of 0 bytes. {fix}")
    return data


def read_state(path: str | os.PathLike[str], system: str | System | None = None) -> bytes:
    """Read a ``.state`` file and return the serialized core state.

    Args:
        path: The file.
        system: The system whose core it is for, if known: its ``state_max`` caps it.

    Raises:
        StateError: The file is missing, empty, not gzip, truncated, corrupt or too large.
    """
    return read_state_file(path, system).data


def read_state_file(path: str | os.PathLike[str], system: str | System | None = None) -> StateFile:
    """Read a ``.state`` file: the serialized core state, and retrokit's record if it has one.

    Args:
        path: The file.
        system: The system whose core it is for, if known: a state larger than its core writes
            (``state_max``) is refused before it is inflated whole.

    Raises:
        StateError: The file is missing, empty, not gzip, truncated, corrupt or too large.
    """
    path = Path(path)
    try:  # a FIFO would block, a device never end, a loop never resolve
        blob = read_regular_file(path, "a save state file", MAX_STATE_FILE_SIZE)
    except FileSystemError as exc:
        raise StateError(f"{exc} It is not a save state.") from None
    return StateFile(decompress_state(blob, source=str(path), system=system), state_record(blob))


@dataclass(frozen=True)
class StateRecord:
    """What retrokit records in a state it writes.

    Attributes:
        game: The game's name, ``<Name>-<System>``.
        rom_sha1: The SHA-1 of the ROM the state was made on.
        sha256: The SHA-256 of the serialized state, so a file changed since is told apart.
    """

    game: str
    rom_sha1: str
    sha256: str

    @classmethod
    def of(cls, game: str, rom_sha1: str, data: bytes) -> StateRecord:
        """The record of ``data``, a state of ``game`` made on the ROM with SHA-1 ``rom_sha1``."""
        return cls(game, rom_sha1, hashlib.sha256(data).hexdigest())

    def describes(self, data: bytes) -> bool:
        """Whether ``data`` is exactly the state this record was written with."""
        return hashlib.sha256(data).hexdigest() == self.sha256


@dataclass(frozen=True)
class StateFile:
    """A ``.state`` file's contents: the serialized state, and retrokit's record if it has one."""

    data: bytes
    record: StateRecord | None


_FEXTRA = 4
_RECORD_ID = b"RK"


def state_record(blob: bytes) -> StateRecord | None:
    """Return the record in a gzip-compressed state's header, or ``None`` (stable-retro's states have none)."""
    if len(blob) < 12 or blob[:2] != GZIP_MAGIC or not blob[3] & _FEXTRA:
        return None
    end = 12 + int.from_bytes(blob[10:12], "little")
    at = 12
    while at + 4 <= end:
        size = int.from_bytes(blob[at + 2 : at + 4], "little")
        if blob[at : at + 2] == _RECORD_ID:
            try:
                doc = json.loads(blob[at + 4 : at + 4 + size].decode("utf-8"))
                return StateRecord(str(doc["game"]), str(doc["rom_sha1"]), str(doc["sha256"]))
            except (ValueError, KeyError, TypeError):
                return None  # not ours after all: treat the state as one without a record
        at += 4 + size
    return None


def compress_state(data: bytes, record: StateRecord | None = None) -> bytes:
    """Return ``data`` gzip-compressed the way ``.state`` files are (reproducibly: no timestamp).

    Args:
        data: The serialized state.
        record: What to record in the gzip header's extra field.
    """
    if record is None:
        return gzip.compress(bytes(data), compresslevel=9, mtime=0)
    payload = json.dumps({"game": record.game, "rom_sha1": record.rom_sha1, "sha256": record.sha256}).encode()
    extra = _RECORD_ID + len(payload).to_bytes(2, "little") + payload
    # ID1 ID2, deflate, FEXTRA, mtime 0, XFL 2 (best compression), OS 255 (unknown), as gzip.compress writes.
    header = GZIP_MAGIC + bytes([8, _FEXTRA]) + bytes(4) + bytes([2, 255]) + len(extra).to_bytes(2, "little") + extra
    deflate = zlib.compressobj(9, zlib.DEFLATED, -zlib.MAX_WBITS)
    body = deflate.compress(bytes(data)) + deflate.flush()
    trailer = (zlib.crc32(data) & 0xFFFFFFFF).to_bytes(4, "little") + (len(data) & 0xFFFFFFFF).to_bytes(4, "little")
    return header + body + trailer


def write_state(
    path: str | os.PathLike[str], data: bytes, *, overwrite: bool = False, record: StateRecord | None = None
) -> Path:
    """Write a serialized core state to a ``.state`` file, gzip-compressed.

    The file is written to a temporary file and renamed into place. Writing the
    same state again is a no-op.

    Args:
        path: The destination file.
        data: The serialized core state (uncompressed).
        overwrite: Replace a different existing file.
        record: What to record in the file (see :class:`StateRecord`).

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
    atomic_write(path, compress_state(data, record), overwrite=overwrite)
    return path


def _conflict(path: Path) -> FileConflictError:
    return FileConflictError(
        f"Expected no file at {str(path)!r} or the same state; found a different file. {REPLACE_HINT}"
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
