"""A state file copied into the game's folder while it is open is found at once (issue 31 item 8)."""

from __future__ import annotations

import shutil
from pathlib import Path

from starlette.testclient import TestClient

from retrokit import paths
from retrokit.data.games import find_game
from retrokit.studio.app import create_app
from retrokit.studio.session import Session

DASHER = Path(__file__).resolve().parent.parent / "games" / "Dasher-Genesis"
TOKEN, PORT = "rescan-token", 8769


def test_a_state_copied_in_after_the_folder_was_listed_is_found(tmp_path):
    folder = tmp_path / "Dasher-Genesis"
    shutil.copytree(DASHER, folder, ignore=shutil.ignore_patterns("movies"))
    game = find_game(str(folder))
    assert game.state_path("Zone1.Act1").name == "Zone1.Act1.state"  # the folder is listed now
    shutil.copy(folder / "Zone2.Act1.state", folder / "Copied.state")
    assert game.state_path("Copied") == folder / "Copied.state"


def test_the_studio_loads_a_state_copied_in_while_it_runs(tmp_path, monkeypatch):
    games = tmp_path / "games"
    shutil.copytree(DASHER, games / "Dasher-Genesis", ignore=shutil.ignore_patterns("movies"))
    monkeypatch.setenv(paths.GAMES_ENV, str(games))
    monkeypatch.setenv(paths.DATA_ENV, str(tmp_path / "data"))
    session = Session("Dasher-Genesis", "Zone1.Act1")
    session.paused = True
    app = create_app(session, token=TOKEN, port=PORT)
    with TestClient(app, base_url=f"http://127.0.0.1:{PORT}", headers={"X-Retrokit-Token": TOKEN}) as client:
        assert client.post("/api/states/load", json={"name": "Zone1.Act2"}).status_code == 200
        shutil.copy(games / "Dasher-Genesis" / "Zone3.Act1.state", games / "Dasher-Genesis" / "Copied.state")
        answer = client.post("/api/states/load", json={"name": "Copied"})
        assert answer.status_code == 200, answer.text
