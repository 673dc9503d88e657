"""``new`` and the studio's New game take only a ROM file, and a failed ``new`` leaves nothing (issue 31 item 3)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from starlette.testclient import TestClient

from retrokit import paths
from retrokit.cli import main
from retrokit.studio.app import create_app
from retrokit.studio.session import Session

AIRSTRIKER_NAME = "Airstriker-Genesis"
TOKEN, PORT = "new-token", 8767


@pytest.fixture
def data(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv(paths.DATA_ENV, str(tmp_path / "data"))
    monkeypatch.delenv(paths.GAMES_ENV, raising=False)
    return tmp_path / "data"


def test_a_rom_of_another_system_leaves_no_half_made_game(data, airstriker_rom, tmp_path, capsys):
    rom = shutil.copy(airstriker_rom, tmp_path / "air.md")
    assert main(["new", str(rom), "--name", "Air-Nes", "--system", "Nes"]) == 2
    err = capsys.readouterr().err
    # Refused by the ROM's own header (a Genesis ROM has no iNES one), before anything is made.
    assert "Expected a Nes ROM" in err and "Move that file away" not in err, err
    assert len(err.strip().splitlines()) == 1
    assert not (data / "games" / "Air-Nes").exists() and not (data / "roms" / "Air-Nes").exists()
    assert main(["new", str(rom), "--name", "Air-Nes", "--system", "Nes"]) == 2  # the same error again: no folder


def test_a_file_that_is_not_what_its_size_says_is_no_rom(data, capsys):
    assert main(["new", "/proc/self/environ", "--name", "Env-Genesis", "--system", "Genesis"]) == 2
    assert "found " in capsys.readouterr().err
    assert not (data / "games").exists() and not (data / "roms").exists()


def test_the_studio_copies_no_proc_file_into_the_data_folder(data, monkeypatch):
    monkeypatch.setenv("RETROKIT_STUDIO_SECRET", "do-not-copy-me")
    session = Session("Dasher-Genesis", "Zone1.Act1")
    session.paused = True
    app = create_app(session, token=TOKEN, port=PORT)
    with TestClient(app, base_url=f"http://127.0.0.1:{PORT}", headers={"X-Retrokit-Token": TOKEN}) as client:
        answer = client.post("/api/newgame", json={"rom": "/proc/self/environ", "name": "Env-Genesis",
                                                   "system": "Genesis", "open": False})  # fmt: skip
    assert answer.status_code == 400 and answer.json()["kind"] == "RomError", answer.text
    leaked = [p for p in data.rglob("*") if p.is_file() and b"do-not-copy-me" in p.read_bytes()]
    assert not leaked and not (data / "games" / "Env-Genesis").exists()
