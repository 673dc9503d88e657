"""The studio's tools on a real Dasher session, through Starlette's TestClient: fixtures and helpers.

Each test runs the studio's application on a copy of Dasher's folder
(anything written lands there) and a data folder of its own (scenario
drafts), with the session paused so that only what a test does moves the
game. tests/test_studio_tools.py and tests/test_studio_tools_scenario.py
make their fixtures (``data``, ``game``, ``client``) of the functions here with :func:`fixtures`.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from starlette.testclient import TestClient

from retrokit import paths
from retrokit.studio.app import create_app
from retrokit.studio.session import Session

DASHER = Path(__file__).resolve().parent.parent / "games" / "Dasher-Genesis"
TOKEN, PORT = "tools-token", 8765
LIVES, P1_X = 0xFF002B, 0xFF0020


def data_folder(tmp_path_factory) -> Path:
    """A data folder of the module's own, with a copy of the installed data folder's cores (state probes kept across
    tests; a copy, as retrokit reads no record through a link in the data folder)."""
    folder = tmp_path_factory.mktemp("data")
    cores = paths.data_dir() / "cores"
    if cores.is_dir():
        shutil.copytree(cores, folder / "cores", ignore=shutil.ignore_patterns("*.log"))
    return folder


def game_copy(tmp_path, data, monkeypatch) -> Path:
    """A copy of Dasher's folder, found first by name; returns its game.yaml."""
    games = tmp_path / "games"
    shutil.copytree(DASHER, games / "Dasher-Genesis", ignore=shutil.ignore_patterns("movies"))
    monkeypatch.setenv(paths.GAMES_ENV, str(games))
    monkeypatch.setenv(paths.DATA_ENV, str(data))
    return games / "Dasher-Genesis" / "game.yaml"


def open_studio(session: Session) -> TestClient:
    session.paused = True  # only the tests move the game
    app = create_app(session, token=TOKEN, port=PORT)
    return TestClient(app, base_url=f"http://127.0.0.1:{PORT}", headers={"X-Retrokit-Token": TOKEN})


def running_client(game):
    """The studio's application on a new session of that copy, at Zone1.Act1, paused."""
    with open_studio(Session("Dasher-Genesis", "Zone1.Act1")) as client:
        yield client


def fixtures() -> tuple:
    """The fixtures ``data`` (module), ``game`` and ``client``, to assign to names in a test module."""
    return (
        pytest.fixture(data_folder, scope="module", name="data"),
        pytest.fixture(game_copy, name="game"),
        pytest.fixture(running_client, name="client"),
    )


def ok(response) -> dict:
    assert response.status_code in (200, 202), response.text
    return response.json()


def refused(response, status: int = 400) -> dict:
    """A 4xx JSON error of one line (and a RetrokitError's class)."""
    assert response.status_code == status, response.text
    body = response.json()
    assert body["error"] and "\n" not in body["error"] and body["kind"].endswith("Error"), body
    return body


def step(client: TestClient, frames: int, buttons: list[str] | None = None) -> None:
    ok(client.post("/api/play/buttons", json={"buttons": buttons or []}))
    ok(client.post("/api/play/step", json={"frames": frames}))
    ok(client.post("/api/play/buttons", json={"buttons": []}))


def fields(client: TestClient) -> dict[str, dict]:
    return {row["name"]: row for row in ok(client.get("/api/fields"))["fields"]}
