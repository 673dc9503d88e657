"""Save-state files: the wheel's states read unchanged, bad files give clear errors, writes are safe."""

from __future__ import annotations

import gzip
from pathlib import Path

import pytest

from retrokit import paths
from retrokit.data.states import compress_state, read_state, write_state
from retrokit.errors import FileConflictError, StateError

STABLE = paths.wheel_dir() / "data" / "stable"
SONIC_FOLDERS = ("SonicTheHedgehog-Genesis-v0", "SonicTheHedgehog2-Genesis-v0", "SonicAndKnuckles3-Genesis-v0")
GENESIS_STATE_SIZE = 1_036_288  # Genesis Plus GX 1.7.5's serialized state, as shipped in stable-retro 1.0.1
WHEEL_STATES = sorted(p for folder in SONIC_FOLDERS for p in (STABLE / folder).glob("*.state")) + [
    STABLE / "Airstriker-Genesis-v0" / "Level1.state"
]
LEVEL1 = STABLE / "Airstriker-Genesis-v0" / "Level1.state"


def test_the_wheel_ships_58_sonic_states_and_level1():
    assert len(WHEEL_STATES) == 59


@pytest.mark.parametrize("path", WHEEL_STATES, ids=lambda p: f"{p.parent.name.removesuffix('-v0')}/{p.stem}")
def test_wheel_states_read_unchanged(path):
    data = read_state(path)
    assert len(data) == GENESIS_STATE_SIZE
    assert data.startswith(b"GENPLUS-GX 1.7.5")
    assert data == gzip.decompress(path.read_bytes())


def _corrupt(blob: bytes, kind: str) -> bytes:
    if kind == "empty":
        return b""
    if kind == "raw":
        return gzip.decompress(blob)
    if kind == "truncated":
        return blob[: len(blob) // 2]
    if kind == "bad-crc":  # the gzip trailer: CRC-32, then size
        return blob[:-8] + bytes(b ^ 0xFF for b in blob[-8:-4]) + blob[-4:]
    if kind == "bad-deflate":
        mid = len(blob) // 2
        return blob[:20] + b"\xff" * 64 + blob[84:mid] + blob[mid:]
    raise AssertionError(kind)


@pytest.mark.parametrize(
    ("kind", "message"),
    [
        ("empty", "found an empty file"),
        ("raw", "starting with bytes 1f 8b); found 1036288 bytes starting with 47 45 4e 50"),
        ("truncated", "the file is truncated"),
        ("bad-crc", "found a corrupt one"),
        ("bad-deflate", "found a corrupt one"),
    ],
)
def test_bad_state_files(tmp_path, kind, message):
    path = tmp_path / "Bad.state"
    path.write_bytes(_corrupt(LEVEL1.read_bytes(), kind))
    with pytest.raises(StateError) as info:
        read_state(path)
    assert message in str(info.value)
    assert str(path) in str(info.value)
    assert "Record the state again" in str(info.value)


def test_missing_state_file(tmp_path):
    with pytest.raises(StateError, match="Expected a readable save state at .*Nope.state"):
        read_state(tmp_path / "Nope.state")


def test_empty_gzip_stream(tmp_path):
    path = tmp_path / "Empty.state"
    path.write_bytes(gzip.compress(b""))
    with pytest.raises(StateError, match="gzip stream of 0 bytes"):
        read_state(path)


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def test_write_then_read_round_trips(tmp_path):
    data = read_state(LEVEL1)
    path = write_state(tmp_path / "sub" / "Copy.state", data)
    assert read_state(path) == data
    assert path.read_bytes() == compress_state(data)  # reproducible: no timestamp in the header
    assert _leftovers(path.parent) == []


def test_writing_the_same_state_again_is_fine(tmp_path):
    path = write_state(tmp_path / "A.state", b"state one")
    before = path.stat().st_mtime_ns
    write_state(path, b"state one")
    assert path.stat().st_mtime_ns == before


def test_no_silent_overwrite(tmp_path):
    path = write_state(tmp_path / "A.state", b"state one")
    with pytest.raises(FileConflictError, match="overwrite=True"):
        write_state(path, b"state two")
    assert read_state(path) == b"state one"
    (tmp_path / "Mine.state").write_bytes(b"a file the user made, not a state")
    with pytest.raises(FileConflictError):
        write_state(tmp_path / "Mine.state", b"state two")
    assert (tmp_path / "Mine.state").read_bytes() == b"a file the user made, not a state"
    write_state(path, b"state two", overwrite=True)
    assert read_state(path) == b"state two"
    assert _leftovers(tmp_path) == []


def test_writing_nothing_is_an_error(tmp_path):
    with pytest.raises(StateError, match="found 0 bytes"):
        write_state(tmp_path / "A.state", b"")
    assert not (tmp_path / "A.state").exists()
