"""Hostile inputs to ``retrokit import``: devices, FIFOs and zip bombs neither hang it nor blow up its memory.

The cases run in a child process with a timeout and an address-space limit
(tests/childproc.py), so a regression fails here instead of hanging the suite:
one child for all of them, each case's command and answer its own.
"""

from __future__ import annotations

import io
import os
import zipfile
from pathlib import Path

import pytest
from bombs import zip_bytes, zip_parts
from childproc import MAX_RSS_MB, Child, run_cli_cases

from retrokit import paths

AIRSTRIKER_ROM = paths.wheel_dir() / "data" / "stable" / "Airstriker-Genesis-v0" / "rom.md"


def _fifo(folder: Path) -> None:
    os.mkfifo(folder / "pipe.md")  # nobody ever writes: reading it blocks forever


def _dev_zero(folder: Path) -> None:
    (folder / "zero.md").symlink_to("/dev/zero")  # reading it never ends


def _zip_with_big_inner_zip(folder: Path) -> None:
    # inner.zip is 1 GiB (one stored member of zeros); the outer zip deflates it to about 1 MiB.
    inner = zip_parts([("big.bin", [1024], False)])
    (folder / "outer.zip").write_bytes(zip_bytes([("inner.zip", inner, True)]))


def _zip_bomb_member(folder: Path) -> None:
    # 1 GiB of zeros deflated to about 1 MiB: a ROM-named member whose real size is far past the cap.
    (folder / "bomb.zip").write_bytes(zip_bytes([("bomb.md", [1024], True)]))


def _lying_zip_header(folder: Path) -> None:
    # The member's header claims 10 bytes; its data inflates to 64 MiB.
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("liar.md", bytes(64 * 2**20))
    data = bytearray(buffer.getvalue())
    for offset in (data.find(b"PK\x03\x04") + 22, data.find(b"PK\x01\x02") + 24):  # uncompressed size fields
        data[offset : offset + 4] = (10).to_bytes(4, "little")
    (folder / "liar.zip").write_bytes(bytes(data))


CASES = {
    "fifo": (_fifo, "not a regular file"),
    "symlink-to-dev-zero": (_dev_zero, "not a regular file"),
    "zip-holding-a-1GiB-inner-zip": (_zip_with_big_inner_zip, "larger than 256 MiB inside a zip"),
    "zip-bomb-member": (_zip_bomb_member, "larger than 32 MiB"),
    "zip-member-lying-about-its-size": (_lying_zip_header, "liar.md"),
}


@pytest.fixture(scope="module")
def imports(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Child, Path]]:
    """``retrokit import`` of each case's folder (and of a FIFO named on the command line), one child for all.

    Each case has its folder and data folder; its answer is its own command's, the child's peak memory bounds each.
    """
    root = tmp_path_factory.mktemp("imports")
    commands, data = {}, {}
    for case, (make, _) in CASES.items():
        folder = root / case / "roms"
        folder.mkdir(parents=True)
        make(folder)
        (folder / "Airstriker.bin").write_bytes(AIRSTRIKER_ROM.read_bytes())  # the good ROM beside it still imports
        data[case] = root / case / "data"
        commands[case] = ["import", "-v", str(folder), "--data-dir", str(data[case])]
    os.mkfifo(root / "pipe.zip")
    data["fifo-named"] = root / "fifo-named-data"
    commands["fifo-named"] = ["import", str(root / "pipe.zip"), "--data-dir", str(data["fifo-named"])]
    answers = run_cli_cases(commands, timeout=120)
    return {case: (answers[case], data[case]) for case in commands}


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_import_skips_hostile_files_quickly_and_in_little_memory(imports, case: str) -> None:
    _, expected = CASES[case]
    child, data = imports[case]
    assert child.returncode == 0, child.describe()
    assert "Airstriker-Genesis <- " in child.stdout, child.describe()
    assert expected in child.stdout, child.describe()
    assert child.peak_rss_mb < MAX_RSS_MB, child.describe()
    assert (data / "roms" / "Airstriker-Genesis" / "rom.md").is_file()


def test_a_fifo_named_on_the_command_line_is_skipped(imports) -> None:
    child, _ = imports["fifo-named"]
    assert child.returncode == 0, child.describe()
    assert "not a regular file" in child.stdout, child.describe()


def test_import_shows_a_progress_bar_on_a_terminal(tmp_path: Path, capsys, monkeypatch) -> None:
    from retrokit.benchmark import progress
    from retrokit.cli import main

    monkeypatch.setattr(progress, "is_terminal", lambda: True)  # capsys is no terminal; tests/test_cli_pipes.py: no bar

    folder = tmp_path / "roms"
    folder.mkdir()
    for i in range(3):
        (folder / f"junk{i}.bin").write_bytes(bytes([i]) * 100)
    assert main(["import", str(folder), "--data-dir", str(tmp_path / "data")]) == 0
    err = capsys.readouterr().err
    assert "Searching: " in err and "3 files" in err, err
