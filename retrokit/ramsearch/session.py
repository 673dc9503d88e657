"""The session file: a RAM search saved between commands.

Each ``retrokit ramsearch`` command runs in its own process, reading the
session file, doing one thing and writing it back, so a search can be
scripted and resumed. The file is a numpy ``.npz`` archive (a zip) holding:

- ``meta``: JSON: the format's name and version, the game, its ROM's SHA-1,
  the start state, the searched types, the RAM regions, each snapshot's label,
  the history's filters, and the emulator state's SHA-256 (a state that does
  not match it is run in a child process before it is loaded);
- ``emulator_state``: the core's serialized state now;
- ``start_state`` and ``inputs``: the state the inputs played since began at
  (the last state loaded), and those inputs as runs of frames (one row per
  run: its frame count, then a button mask per port), for ``ramsearch movie``;
- ``snapshots``: one row of console-order RAM bytes per snapshot;
- the candidates now, before each filter that can be undone, and after each
  one that can be redone: the alive bits of every (type, position), packed,
  and the scale mask of each alive candidate (bit ``i`` for the meta's
  ``scales[i]``).

It is written to a temporary file and renamed into place, so it is never
half-written. Reading checks everything and says what is wrong in one line,
before it allocates: only a regular file of at most :data:`MAX_FILE` bytes is
read (a FIFO or ``/dev/zero`` never is), and each array's header is held to
the bytes its member really has before numpy reads it.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from retrokit.errors import FieldTypeError, FileConflictError, FileSystemError, SessionError
from retrokit.paths import atomic_write, require_regular_file
from retrokit.ramsearch.candidates import Candidates, Packed
from retrokit.ramsearch.scales import MASK_DTYPE, SCALES
from retrokit.ramsearch.types import SEARCH_TYPES, parse_search_types

DEFAULT_SESSION = "ramsearch.session"
FORMAT = "retrokit-ramsearch-session"
VERSION = 2  # 2: scale masks, and the inputs played
MAX_FILE = 1 << 26  # 64 MiB compressed: a session of a thousand snapshots of 64 KiB takes a few
MAX_UNPACKED = 1 << 28  # 256 MiB: a bigger archive is not one this tool wrote for a console's RAM
MAX_META = 1 << 22  # 4 MiB of JSON: labels and filter names of tens of thousands of snapshots
MAX_CANDIDATES = 1 << 27  # 4 MiB of RAM as 32 types (3.5 MiB as 38): their flags and scales take 256 MiB
_START = "Start a new search with: retrokit ramsearch new GAME"


@dataclass
class SessionData:
    """Everything a session file holds."""

    game: str
    rom_sha1: str
    state: str | None
    types: tuple[str, ...]
    regions: tuple[tuple[int, int], ...]
    emulator_state: bytes
    snapshots: np.ndarray
    labels: list[str]
    candidates: Candidates
    history: list[tuple[str, Candidates | Packed]] = field(default_factory=list)
    redo: list[tuple[str, Candidates | Packed]] = field(default_factory=list)
    state_sha256: str = ""  # what the file says the emulator state's SHA-256 is (read, never trusted blindly)
    start_state: bytes = b""  # the state the inputs begin at
    inputs: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=np.uint32))  # runs: frames, masks
    unreplayable: str | None = None  # why the inputs cannot reproduce the state now (a poke), if they cannot


def _store(prefix: str, candidates: Candidates | Packed, arrays: dict[str, np.ndarray]) -> None:
    packed = candidates.pack() if isinstance(candidates, Candidates) else candidates
    arrays[f"{prefix}_alive"], arrays[f"{prefix}_scale"] = packed.bits, packed.scales


def _load(prefix: str, archive, types: int, size: int, scales: list[int]) -> Packed:
    """Packed candidates, their scale masks mapped from the file's scale list (bit ``i``: ``scales[i]``) to this version's."""
    stored = archive[f"{prefix}_scale"]
    if stored.dtype != MASK_DTYPE:
        raise SessionError(f"expected scale masks of {MASK_DTYPE}; found {stored.dtype}. {_START}")
    if len(stored) and int(np.bitwise_or.reduce(stored)) >> len(scales):
        raise SessionError(
            f"expected scale masks of the {len(scales)} scales the file lists; found more bits. {_START}"
        )
    if scales == list(range(len(scales))):  # a file of this version's scales, in its order: nothing to map
        masks = stored  # (the bit-by-bit mapping took 25 ms an array, and a command reads every undo step's)
    else:
        masks = np.zeros(len(stored), dtype=MASK_DTYPE)
        for bit, index in enumerate(scales):
            masks |= ((stored >> MASK_DTYPE.type(bit)) & MASK_DTYPE.type(1)) << MASK_DTYPE.type(index)
    packed = Packed(archive[f"{prefix}_alive"], masks)
    Candidates.unpack(packed, types, size)  # checks it whole now, not at an undo
    return packed


def encode_session(data: SessionData) -> bytes:
    """The bytes of a session file."""
    meta = {
        "format": FORMAT,
        "version": VERSION,
        "game": data.game,
        "rom_sha1": data.rom_sha1,
        "state": data.state,
        "types": list(data.types),
        "regions": [list(r) for r in data.regions],
        "labels": data.labels,
        "scales": [scale.label for scale in SCALES],
        "state_sha256": hashlib.sha256(data.emulator_state).hexdigest(),
        "history": [label for label, _ in data.history],
        "redo": [label for label, _ in data.redo],
        "unreplayable": data.unreplayable,
    }
    arrays = {
        "meta": np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8),
        "emulator_state": np.frombuffer(data.emulator_state, dtype=np.uint8),
        "start_state": np.frombuffer(data.start_state, dtype=np.uint8),
        "inputs": np.ascontiguousarray(data.inputs, dtype=np.uint32),
        "snapshots": data.snapshots,
    }
    _store("now", data.candidates, arrays)
    for i, (_, packed) in enumerate(data.history):
        _store(f"history{i}", packed, arrays)
    for i, (_, packed) in enumerate(data.redo):
        _store(f"redo{i}", packed, arrays)
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)
    return buffer.getvalue()


def write_session(path: str | os.PathLike[str], data: SessionData, *, overwrite: bool = True) -> None:
    """Write a session file atomically, replacing the one there unless ``overwrite`` is false.

    Raises:
        FileConflictError: ``path`` exists and ``overwrite`` is false.
    """
    atomic_write(path, encode_session(data), overwrite=overwrite)


def read_session(path: str | os.PathLike[str]) -> SessionData:
    """Read a session file.

    Raises:
        SessionError: The file is missing, unreadable, not a session file, or corrupt.
    """
    path = Path(path)
    blob = _read_file(path)
    try:
        return _decode(blob)
    except SessionError as exc:
        raise SessionError(f"{path}: {exc}") from None
    except (zipfile.BadZipFile, ValueError, KeyError, EOFError, OSError, TypeError, IndexError, RecursionError) as exc:
        # RecursionError: JSON nested past Python's stack, which no file of this tool holds
        raise SessionError(
            f"{path}: expected a RAM search session file; found a corrupt one ({type(exc).__name__}: "
            f"{str(exc)[:200]}). {_START}"
        ) from None


def _read_file(path: Path) -> bytes:
    """The bytes of a session file: a regular file (symlinks followed) of at most :data:`MAX_FILE` bytes."""
    if not path.exists():
        raise SessionError(
            f"Expected a RAM search session at {str(path)!r}; found no file. {_START} "
            f"(or pass --session with the file you started)."
        )
    try:
        require_regular_file(path, "a RAM search session file")
        with path.open("rb") as f:
            blob = f.read(MAX_FILE + 1)
    except FileSystemError as exc:
        raise SessionError(f"{exc} {_START}") from None
    except OSError as exc:
        raise SessionError(
            f"Expected a readable session file at {str(path)!r}; found an error: {exc.strerror or exc}."
        ) from None
    if len(blob) > MAX_FILE:
        raise SessionError(
            f"{path}: expected a session file of at most {MAX_FILE >> 20} MiB; found a bigger file. {_START}"
        )
    return blob


def _check_arrays(archive: zipfile.ZipFile) -> None:
    """Hold every array's header to its member's size, so a header that declares a huge shape is never allocated.

    Raises:
        SessionError: A member is not a plain ``.npy`` array whose shape fills exactly its bytes.
    """
    from numpy.lib import format as npy

    for info in archive.infolist():
        with archive.open(info) as member:
            version = npy.read_magic(member)
            if version == (1, 0):
                shape, _, dtype = npy.read_array_header_1_0(member)
            elif version == (2, 0):
                shape, _, dtype = npy.read_array_header_2_0(member)
            else:
                raise SessionError(f"expected arrays of .npy format 1.0 or 2.0; found {version} in {info.filename}.")
            declared = math.prod(shape) * dtype.itemsize
            present = info.file_size - member.tell()
        if dtype.hasobject or declared != present:
            raise SessionError(
                f"expected each array to hold the bytes its header declares; {info.filename} declares shape "
                f"{str(shape)[:80]} of {dtype} ({declared:,} bytes) over {present:,} bytes. {_START}"
            )


def _decode(blob: bytes) -> SessionData:
    if not zipfile.is_zipfile(io.BytesIO(blob)):
        raise SessionError(
            f"expected a RAM search session file (a zip archive); found {len(blob)} bytes of something else. {_START}"
        )
    with zipfile.ZipFile(io.BytesIO(blob)) as archive:
        unpacked = sum(info.file_size for info in archive.infolist())
        if unpacked > MAX_UNPACKED:
            raise SessionError(
                f"expected a session of at most {MAX_UNPACKED >> 20} MiB unpacked; found {unpacked >> 20} MiB. {_START}"
            )
        meta_info = next((info for info in archive.infolist() if info.filename == "meta.npy"), None)
        if meta_info is not None and meta_info.file_size > MAX_META:
            raise SessionError(  # its JSON becomes Python objects, tens of times its size
                f"expected a session's description (meta) of at most {MAX_META >> 20} MiB; found "
                f"{meta_info.file_size:,} bytes. {_START}"
            )
        _check_arrays(archive)
    with np.load(io.BytesIO(blob), allow_pickle=False) as archive:
        if "meta" not in archive.files:
            raise SessionError(f"expected a RAM search session file; found a zip without its 'meta' member. {_START}")
        meta = json.loads(bytes(archive["meta"]).decode())
        if not isinstance(meta, dict) or meta.get("format") != FORMAT:
            raise SessionError(f"expected a RAM search session file; found another kind of archive. {_START}")
        if meta.get("version") != VERSION:
            raise SessionError(f"expected session format version {VERSION}; found {meta.get('version')!r}. {_START}")
        types, regions = tuple(str(t) for t in meta["types"]), tuple((int(s), int(n)) for s, n in meta["regions"])
        try:
            parse_search_types(types)
        except FieldTypeError as exc:
            raise SessionError(f"expected the searched type codes; found {list(types)} ({exc}) {_START}") from None
        size = sum(n for _, n in regions)
        if not 0 < len(types) <= len(SEARCH_TYPES) * 2 or not 0 < size or len(types) * size > MAX_CANDIDATES:
            raise SessionError(
                f"expected at most {MAX_CANDIDATES:,} candidates (types times RAM bytes); found {len(types)} types "
                f"over {size:,} bytes. {_START}"
            )
        known = {scale.label: index for index, scale in enumerate(SCALES)}
        missing = [label for label in meta["scales"] if label not in known]
        if missing:
            raise SessionError(f"expected scales this version knows; found {missing}. {_START}")
        scales = [known[label] for label in meta["scales"]]
        snapshots = archive["snapshots"]
        if snapshots.dtype != np.uint8 or snapshots.ndim != 2 or snapshots.shape[1] != size:
            raise SessionError(
                f"expected snapshots of {size} bytes; found an array of shape {snapshots.shape}. {_START}"
            )
        if not len(snapshots):
            raise SessionError(f"expected at least one snapshot (a search starts with one); found none. {_START}")
        if len(meta["labels"]) != len(snapshots):
            raise SessionError(
                f"expected a label per snapshot; found {len(meta['labels'])} for {len(snapshots)}. {_START}"
            )
        return SessionData(
            game=str(meta["game"]),
            rom_sha1=str(meta["rom_sha1"]),
            state=meta["state"],
            types=types,
            regions=regions,
            emulator_state=archive["emulator_state"].tobytes(),
            snapshots=snapshots,
            labels=[str(label) for label in meta["labels"]],
            state_sha256=str(meta.get("state_sha256", "")),
            start_state=archive["start_state"].tobytes(),
            inputs=_inputs(archive["inputs"]),
            unreplayable=None if meta["unreplayable"] is None else str(meta["unreplayable"]),
            candidates=Candidates.unpack(_load("now", archive, len(types), size, scales), len(types), size),
            history=[
                (str(label), _load(f"history{i}", archive, len(types), size, scales))
                for i, label in enumerate(meta["history"])
            ],
            redo=[
                (str(label), _load(f"redo{i}", archive, len(types), size, scales))
                for i, label in enumerate(meta["redo"])
            ],
        )


def _inputs(runs: np.ndarray) -> np.ndarray:
    """The runs of inputs, checked: a frame count of at least 1, then a button mask per port."""
    if runs.dtype != np.uint32 or runs.ndim != 2 or runs.shape[1] < 2 or (len(runs) and runs[:, 0].min() < 1):
        raise SessionError(
            f"expected runs of inputs (frames, then a mask per port); found an array of shape {runs.shape}. {_START}"
        )
    return runs


def check_new_session(path: str | os.PathLike[str], game: str, *, force: bool = False) -> None:
    """Check a new search of ``game`` may be written at ``path``: the replacement policy of ``ramsearch new``.

    A free path may; a session (or anything else) already there only with ``force``.

    Raises:
        FileConflictError: Something is at ``path`` and ``force`` is false.
        SessionError: A session of another game is there and ``force`` is false.
    """
    path = Path(path)
    if force or not (path.exists() or path.is_symlink()):
        return
    try:
        old = read_session(path)
    except SessionError:
        raise FileConflictError(
            f"Expected no file at {path}; found one that is not a session. Pass --session OTHER, or --force to replace it."
        ) from None
    if old.game != game:
        raise SessionError(
            f"Expected {path} to be free or a session of {game}; found a session of another game, {old.game}. "
            f"Pass --session OTHER for {game}, or --force to replace it."
        )
    raise FileConflictError(
        f"Expected no session at {path}; found one of {old.game} with {len(old.labels)} snapshot(s). "
        "Pass --force to start over, or --session OTHER."
    )
