"""The session file: a RAM search saved between commands.

Each ``retrokit ramsearch`` command runs in its own process, reading the
session file, doing one thing and writing it back, so a search can be
scripted and resumed. The file is a numpy ``.npz`` archive (a zip) holding:

- ``meta``: JSON: the format's name and version, the game, its ROM's SHA-1,
  the start state, the searched types, the RAM regions, each snapshot's label,
  the history's filters, and the emulator state's SHA-256 (a state that does
  not match it is run in a child process before it is loaded);
- ``emulator_state``: the core's serialized state now;
- ``snapshots``: one row of console-order RAM bytes per snapshot;
- the candidates now, before each filter that can be undone, and after each
  one that can be redone: the alive bits of every (type, position), packed,
  and the scale index of each alive candidate.

It is written to a temporary file and renamed into place, so it is never
half-written. Reading checks everything and says what is wrong in one line.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from retrokit.errors import FieldTypeError, SessionError
from retrokit.paths import atomic_write
from retrokit.ramsearch.candidates import Candidates, Packed
from retrokit.ramsearch.scales import SCALES
from retrokit.ramsearch.types import SEARCH_TYPES, parse_search_types

DEFAULT_SESSION = "ramsearch.session"
FORMAT = "retrokit-ramsearch-session"
VERSION = 1
MAX_UNPACKED = 1 << 28  # 256 MiB: a bigger archive is not one this tool wrote for a console's RAM
MAX_CANDIDATES = 1 << 27  # 4 MiB of RAM as 32 types: their flags and scales take 256 MiB
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


def _store(prefix: str, candidates: Candidates | Packed, arrays: dict[str, np.ndarray]) -> None:
    packed = candidates.pack() if isinstance(candidates, Candidates) else candidates
    arrays[f"{prefix}_alive"], arrays[f"{prefix}_scale"] = packed.bits, packed.scales


def _load(prefix: str, archive, types: int, size: int, scales: np.ndarray) -> Packed:
    """Packed candidates, their scale indices mapped from the file's scale list to this version's."""
    packed = Packed(archive[f"{prefix}_alive"], scales[archive[f"{prefix}_scale"].astype(np.int64) + 1])
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
    }
    arrays = {
        "meta": np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8),
        "emulator_state": np.frombuffer(data.emulator_state, dtype=np.uint8),
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
    try:
        blob = path.read_bytes()
    except FileNotFoundError:
        raise SessionError(
            f"Expected a RAM search session at {str(path)!r}; found no file. {_START} "
            f"(or pass --session with the file you started)."
        ) from None
    except OSError as exc:
        raise SessionError(
            f"Expected a readable session file at {str(path)!r}; found an error: {exc.strerror or exc}."
        ) from None
    try:
        return _decode(blob)
    except SessionError as exc:
        raise SessionError(f"{path}: {exc}") from None
    except (zipfile.BadZipFile, ValueError, KeyError, EOFError, OSError, TypeError, IndexError) as exc:
        raise SessionError(
            f"{path}: expected a RAM search session file; found a corrupt one ({type(exc).__name__}: {exc}). {_START}"
        ) from None


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
        scales = np.array([-1] + [known[label] for label in meta["scales"]], dtype=np.int8)
        snapshots = archive["snapshots"]
        if snapshots.dtype != np.uint8 or snapshots.ndim != 2 or snapshots.shape[1] != size:
            raise SessionError(
                f"expected snapshots of {size} bytes; found an array of shape {snapshots.shape}. {_START}"
            )
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
