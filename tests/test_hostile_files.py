"""File-system failures through the command line: one line of error and the error status, never a traceback.

Files where folders should be (the data folder, an output's folder), folders
where files should be (a game's rom.md), an output without a suffix, and a
folder that cannot be written. The machine runs as root, so an unwritable
folder is one in /proc, where nothing can be created.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest
from childproc import run_cli

from retrokit import paths
from retrokit.cli import ERROR_STATUS, main
from retrokit.errors import FileSystemError
from retrokit.movie import Movie, write_bk2

DASHER = Path(__file__).resolve().parent.parent / "games" / "Dasher-Genesis"
AIRSTRIKER_ROM = paths.wheel_dir() / "data" / "stable" / "Airstriker-Genesis-v0" / "rom.md"
SCENARIO_JSON = paths.wheel_dir() / "data" / "stable" / "Airstriker-Genesis-v0" / "scenario.json"


@pytest.fixture
def place(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A folder with a plain file ``afile`` and a short Dasher movie ``m.bk2``; the working directory."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    (tmp_path / "afile").write_text("not a folder")
    write_bk2(tmp_path / "m.bk2", Movie("Dasher-Genesis", "Genesis", 1, None, [(0,)] * 4))
    return tmp_path


def _rom_md_a_folder(place: Path, monkeypatch: pytest.MonkeyPatch) -> list[str]:
    folder = place / "games" / "Dashless-Genesis"
    folder.mkdir(parents=True)
    shutil.copy(DASHER / "game.yaml", folder / "game.yaml")
    (folder / "rom.md").mkdir()
    monkeypatch.setenv("RETROKIT_GAMES", str(place / "games"))
    return ["integrate", "Dashless-Genesis"]


def _import_a_folder_named_rom_md(place: Path, monkeypatch: pytest.MonkeyPatch) -> list[str]:
    (place / "rom.md").mkdir()
    return ["import", str(place / "rom.md"), str(place / "afile" / "missing.md")]


CASES = {
    "rom.md-is-a-folder": (_rom_md_a_folder, "ROM"),
    # a path that does not exist (here under a file) is a one-line error, exit 2 (issue 20), before any is searched
    "import-a-folder-named-rom.md": (_import_a_folder_named_rom_md, "no such path"),
    "data-folder-is-a-file": (lambda place, mp: mp.setenv("RETROKIT_DATA", str(place / "afile"))
                              or ["import", str(AIRSTRIKER_ROM)], "a file where one of its parent folders should be"),
    "output-without-suffix-is-a-file": (lambda place, mp: ["playback", "m.bk2", "afile"], "a file that is none of them"),
    "gif-output-under-a-file": (lambda place, mp: ["playback", "m.bk2", "afile/out.gif"], "a file, not a folder"),
    "png-output-under-a-file": (lambda place, mp: ["playback", "m.bk2", "afile/frames"], "parent folders"),
    "unwritable-output-folder": (lambda place, mp: ["playback", "m.bk2", "/proc/out.gif"], "cannot be written"),
    "convert-output-under-a-file": (lambda place, mp: ["convert", str(SCENARIO_JSON), "afile/x.yaml"], "a file, not a folder"),
    "demo-out-is-a-file": (lambda place, mp: ["demo", "--timesteps", "1", "--out", "afile"], "a file, not a folder"),
    "evaluate-out-is-a-file": (lambda place, mp: ["evaluate", "--timesteps", "1", "--out", "afile"],
                               "a file, not a folder"),
    "evaluate-out-under-a-file": (lambda place, mp: ["evaluate", "--timesteps", "1", "--out", "afile/run"],
                                  "parent folders"),
}


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_a_file_system_failure_is_one_line(place: Path, monkeypatch: pytest.MonkeyPatch, capsys, case: str) -> None:
    setup, message = CASES[case]
    status = main(setup(place, monkeypatch))
    err = capsys.readouterr().err
    if message is None:  # nothing to fail on: skipped with a reason, not a crash
        assert status == 0, err
        return
    assert status == ERROR_STATUS, err
    lines = err.strip().splitlines()
    assert lines[-1].startswith("retrokit: error:") and message in lines[-1], err
    assert "Traceback" not in err


def test_the_demo_refuses_a_bad_out_before_playing(place: Path, capsys) -> None:
    assert main(["demo", "--timesteps", "1", "--out", "afile"]) == ERROR_STATUS
    assert "step" not in capsys.readouterr().err  # no progress bar: nothing was played


def test_the_demo_says_when_every_name_is_taken(place: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from retrokit.commands import demo

    monkeypatch.setattr(Path, "exists", lambda self: True)
    monkeypatch.setattr(Path, "is_dir", lambda self: True)
    monkeypatch.setattr(Path, "iterdir", lambda self: iter([self]))
    with pytest.raises(demo.FileConflictError, match="all 10000 taken"):
        demo.free_folder(place / "retrokit-demo")


def test_atomic_write_names_the_folder_in_the_way(place: Path) -> None:
    with pytest.raises(FileSystemError, match="afile' to write x.bin into; found a file, not a folder"):
        paths.atomic_write(place / "afile" / "x.bin", b"data")
    with pytest.raises(FileExistsError):  # a real conflict is still a FileExistsError
        paths.atomic_write(place / "afile", b"data")


def test_the_cli_turns_a_stray_os_error_into_one_line(capsys, monkeypatch: pytest.MonkeyPatch) -> None:
    from retrokit.commands import games

    def broken(args):
        raise PermissionError(13, "Permission denied", "/somewhere")

    monkeypatch.setattr(games, "run", broken)
    assert main(["games"]) == ERROR_STATUS
    assert capsys.readouterr().err == "retrokit: error: a file operation failed (/somewhere): Permission denied.\n"


SPECIAL = {"fifo": lambda path: os.mkfifo(path), "symlink-to-dev-zero": lambda path: path.symlink_to("/dev/zero")}
READERS = {"playback-movie": (["playback", "{path}", "out.gif"], ".bk2"), "convert-scenario": (["convert", "{path}"], ".json")}


@pytest.mark.parametrize("special", list(SPECIAL), ids=list(SPECIAL))
@pytest.mark.parametrize("reader", list(READERS), ids=list(READERS))
def test_a_fifo_or_device_given_as_input_is_refused_not_read(tmp_path: Path, special: str, reader: str) -> None:
    args, suffix = READERS[reader]
    path = tmp_path / f"input{suffix}"
    SPECIAL[special](path)
    child = run_cli([a.format(path=path) for a in args], timeout=30, cwd=tmp_path)
    assert child.returncode == ERROR_STATUS, child.describe()
    assert "which is not a file retrokit reads" in child.stderr.strip().splitlines()[-1], child.describe()
