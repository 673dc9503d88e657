"""``retrokit ramsearch`` on hostile input (issue 19 §6): one line of a retrokit error, no hang, under 500 MB.

Each test builds its input: a FIFO, a symlink to ``/dev/zero``, an array
header that declares a huge shape, JSON nested past Python's stack, a session
with no snapshot, a game.yaml behind a symlink, a field name of 10,000
characters, and ``--press`` given twice.
"""

from __future__ import annotations

import io
import json
import os
import re
import shutil
import zipfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from childproc import MAX_RSS_MB, Child, run_cli, run_cli_cases

from retrokit import cli
from retrokit.ramsearch import RamSearch
from retrokit.ramsearch.session import DEFAULT_SESSION, encode_session, read_session

REPO = Path(__file__).resolve().parent.parent
DASHER = REPO / "games" / "Dasher-Genesis"


@pytest.fixture(scope="module")
def good_session(tmp_path_factory) -> bytes:
    """The bytes of a Dasher session with one snapshot."""
    path = tmp_path_factory.mktemp("session") / DEFAULT_SESSION
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        search.save(path)
    return path.read_bytes()


def with_member(blob: bytes, name: str, data: bytes) -> bytes:
    """A copy of a session archive with one member's bytes replaced."""
    out = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(blob)) as source, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as target:
        for info in source.infolist():
            target.writestr(info.filename, data if info.filename == name else source.read(info))
    return out.getvalue()


def npy(array: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, array)
    return buffer.getvalue()


def huge_header() -> bytes:
    """A ``.npy`` member whose header declares 64 TiB of snapshots over 16 bytes of data."""
    buffer = io.BytesIO()
    header = {"descr": "|u1", "fortran_order": False, "shape": (1 << 30, 65536)}
    np.lib.format.write_array_header_1_0(buffer, header)
    return buffer.getvalue() + bytes(16)


def deep_json() -> bytes:
    return npy(np.frombuffer(("[" * 100_000 + "]" * 100_000).encode(), dtype=np.uint8))


def check_one_line(child, *expected: str) -> None:
    assert child.returncode == 2, child.describe()
    assert child.stderr.startswith("retrokit: error: ") and child.stderr.count("\n") == 1, child.describe()
    assert "Traceback" not in child.stderr
    for text in expected:
        assert text in child.stderr, child.describe()
    assert child.peak_rss_mb < MAX_RSS_MB, child.describe()


HOSTILE_SESSIONS = {
    "fifo": (lambda path, good: os.mkfifo(path), "found a FIFO"),
    "symlink-to-dev-zero": (lambda path, good: path.symlink_to("/dev/zero"), "found a device"),
    "npy-header-of-a-huge-shape": (
        lambda path, good: path.write_bytes(with_member(good, "snapshots.npy", huge_header())), "declares shape"
    ),
    "json-nested-100000-deep": (
        lambda path, good: path.write_bytes(with_member(good, "meta.npy", deep_json())), "RecursionError"
    ),
    "no-snapshot": (
        lambda path, good: path.write_bytes(with_member(good, "snapshots.npy", npy(np.zeros((0, 65536), np.uint8)))),
        "expected at least one snapshot",
    ),
}
COMMANDS = ["show", "undo"]


@pytest.fixture(scope="module")
def hostile_sessions(tmp_path_factory, good_session) -> dict[str, Child]:
    """``retrokit ramsearch COMMAND --session BAD`` for each hostile session and command, all in one child (under
    the memory cap, its peak a bound on each); each its own command and answer, by ``"COMMAND-CASE"``."""
    commands = {}
    for case, (build, _) in HOSTILE_SESSIONS.items():
        for command in COMMANDS:
            path = tmp_path_factory.mktemp(case) / "bad.session"  # each command its own file: undo may write
            build(path, good_session)
            commands[f"{command}-{case}"] = ["ramsearch", command, "--session", str(path)]
    return run_cli_cases(commands, timeout=120)


@pytest.mark.parametrize("case", list(HOSTILE_SESSIONS))
@pytest.mark.parametrize("command", COMMANDS)
def test_a_hostile_session_file_is_one_line_under_500_mb(hostile_sessions, case, command):
    check_one_line(hostile_sessions[f"{command}-{case}"], HOSTILE_SESSIONS[case][1], "retrokit ramsearch new GAME")


def test_a_session_of_zero_snapshots_is_refused_by_the_api_too(tmp_path, good_session):
    from retrokit.errors import SessionError

    data = read_session(_write(tmp_path / "good.session", good_session))
    bad = _write(tmp_path / "empty.session", encode_session(replace(data, snapshots=data.snapshots[:0], labels=[])))
    with pytest.raises(SessionError, match="expected at least one snapshot"):
        RamSearch.load(bad)


def _write(path: Path, blob: bytes) -> Path:
    path.write_bytes(blob)
    return path


@pytest.fixture
def game_copy(tmp_path: Path, monkeypatch) -> Path:
    """A copy of Dasher's folder in a games folder, and a session of it in the cwd."""
    games = tmp_path / "games"
    shutil.copytree(DASHER, games / "Dasher-Genesis", ignore=shutil.ignore_patterns("movies", "*.state"))
    monkeypatch.chdir(tmp_path)
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        search.save(tmp_path / DEFAULT_SESSION)
    return games / "Dasher-Genesis" / "game.yaml"


def test_save_through_a_symlinked_game_yaml_updates_its_target(tmp_path, game_copy, capsys):
    link = tmp_path / "link.yaml"
    link.symlink_to(game_copy)
    status = cli.main(["ramsearch", "save", "coins", "0xFF0040", "|u1", "--game-file", str(link)])
    assert status == 0, capsys.readouterr().err
    assert link.is_symlink() and link.resolve() == game_copy.resolve()  # the link is still a link
    assert re.search(
        r'\n  coins: +\{address: 0xFF0040, type: "\|u1"\}\n', game_copy.read_text()
    )  # the real file has it


def test_a_game_yaml_that_is_a_fifo_is_refused_not_read(tmp_path, game_copy):
    fifo = tmp_path / "fifo.yaml"
    os.mkfifo(fifo)
    child = run_cli(
        ["ramsearch", "save", "coins", "0xFF0040", "|u1", "--game-file", str(fifo)], timeout=60, cwd=tmp_path
    )
    check_one_line(child, "Expected a game.yaml")


def test_a_field_name_of_10000_characters_is_blamed_on_the_name(game_copy, capsys):
    before = game_copy.read_bytes()
    status = cli.main(["ramsearch", "save", "x" * 10_000, "0xFF0040", "|u1", "--game-file", str(game_copy)])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and len(err) < 400, err
    assert "Expected a field name of at most 64" in err and "syntax error" not in err
    assert game_copy.read_bytes() == before


def test_press_given_twice_holds_both_buttons(game_copy, capsys):
    assert cli.main(["ramsearch", "run", "--press", "B", "--press", "UP", "--frames", "3"]) == 0
    assert capsys.readouterr().out == "Snapshot 1: B UP for 3 frames.\n"
    with RamSearch.load(DEFAULT_SESSION) as search:
        ((frames, masks),) = search.inputs
        assert frames == 3 and masks[0] == search.emulator.system.mask(["B", "UP"])


def test_the_meta_of_a_session_is_plain_json(good_session, tmp_path):
    """The JSON test above replaces a member this tool really reads as JSON."""
    with zipfile.ZipFile(io.BytesIO(good_session)) as archive:
        meta = np.load(io.BytesIO(archive.read("meta.npy")))
    assert json.loads(bytes(meta))["format"] == "retrokit-ramsearch-session"
