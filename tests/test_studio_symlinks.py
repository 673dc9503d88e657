"""Planted symlinks reach nothing outside the game's folders and the data folder through the studio (issue 31 item 2).

A scenario file, a draft, the drafts folder or the game.yaml may be a link
someone planted to a file elsewhere; the studio refuses to read or write
through it, with a one-line 403, and the file outside stays as it was.
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
TOKEN, PORT = "link-token", 8766
SECRET = "# not the studio's: a file outside\nreward: 0\n"


@pytest.fixture
def world(tmp_path, monkeypatch) -> dict[str, Path]:
    games, data, outside = tmp_path / "games", tmp_path / "data", tmp_path / "outside"
    shutil.copytree(DASHER, games / "Dasher-Genesis", ignore=shutil.ignore_patterns("movies"))
    data.mkdir()
    outside.mkdir()
    (outside / "secret.yaml").write_text(SECRET)
    monkeypatch.setenv(paths.GAMES_ENV, str(games))
    monkeypatch.setenv(paths.DATA_ENV, str(data))
    return {"game": games / "Dasher-Genesis", "data": data, "outside": outside}


def studio() -> TestClient:
    session = Session("Dasher-Genesis", "Zone1.Act1")
    session.paused = True
    return TestClient(create_app(session, token=TOKEN, port=PORT), base_url=f"http://127.0.0.1:{PORT}",
                      headers={"X-Retrokit-Token": TOKEN})  # fmt: skip


def refused(answer) -> str:
    assert answer.status_code == 403, answer.text
    body = answer.json()
    assert body["kind"] in ("AccessDeniedError", "PlantedLinkError") and "\n" not in body["error"] and "reward: 0" not in answer.text
    return body["error"]


def test_a_scenario_file_linked_outside_is_not_read(world):
    (world["game"] / "escape.yaml").symlink_to(world["outside"] / "secret.yaml")
    with studio() as client:
        assert "symlink" in refused(client.get("/api/scenario", params={"name": "escape"}))


def test_a_draft_linked_outside_is_not_read(world):
    drafts = world["data"] / "studio" / "drafts" / "Dasher-Genesis"
    drafts.mkdir(parents=True)
    (drafts / "scenario.yaml").symlink_to(world["outside"] / "secret.yaml")
    with studio() as client:
        assert "symlink" in refused(client.get("/api/scenario"))


def test_a_drafts_folder_linked_outside_gets_no_draft(world):
    (world["data"] / "studio").mkdir()
    (world["data"] / "studio" / "drafts").symlink_to(world["outside"], target_is_directory=True)
    with studio() as client:
        refused(client.put("/api/scenario/draft", json={"text": "reward: 1\n"}))
    assert sorted(p.name for p in world["outside"].rglob("*")) == ["secret.yaml"]


def test_a_game_yaml_linked_outside_is_not_written(world):
    game_yaml = world["game"] / "game.yaml"
    shutil.copy(game_yaml, world["outside"] / "game.yaml")
    game_yaml.unlink()
    game_yaml.symlink_to(world["outside"] / "game.yaml")
    before = (world["outside"] / "game.yaml").read_bytes()
    with studio() as client:
        refused(client.post("/api/search/field", json={"name": "planted", "address": 0xFF0100, "type": "|u1"}))
        refused(client.patch("/api/fields/p1_lives", json={"address": 0xFF0101}))
    assert (world["outside"] / "game.yaml").read_bytes() == before


def test_a_made_game_yaml_linked_outside_gets_no_default_state(world, monkeypatch):
    """Set default on a shipped game writes its game.yaml in the data folder (a copy of the shipped one): never through
    a link. (The checkout's Dasher here: a game of the user's own is written where it is.)"""
    monkeypatch.delenv(paths.GAMES_ENV)
    made = world["data"] / "games" / "Dasher-Genesis"
    made.mkdir(parents=True)
    shutil.copy(world["game"] / "game.yaml", world["outside"] / "game.yaml")
    (made / "game.yaml").symlink_to(world["outside"] / "game.yaml")
    before = (world["outside"] / "game.yaml").read_bytes()
    with studio() as client:
        refused(client.post("/api/states/default", json={"name": "Zone1.Act2"}))
    assert (world["outside"] / "game.yaml").read_bytes() == before


@pytest.mark.parametrize("level", ["games", "games/Dasher-Genesis"])
def test_a_made_game_folder_linked_outside_gets_no_field(world, monkeypatch, level):
    """Add field on a shipped game writes its game.yaml copy in the data folder: a planted link at the data folder's
    games/ or at the game's folder there is refused in one line (:func:`retrokit.paths.data_path`), nothing written."""
    monkeypatch.delenv(paths.GAMES_ENV)
    link = world["data"] / level
    link.parent.mkdir(parents=True, exist_ok=True)
    link.symlink_to(world["outside"], target_is_directory=True)
    with studio() as client:
        error = refused(client.post("/api/search/field", json={"name": "planted", "address": 0xFF0100, "type": "|u1"}))
    assert f"'{link}'" in error and "found a symlink" in error
    assert sorted(p.name for p in world["outside"].rglob("*")) == ["secret.yaml"]
    assert (world["outside"] / "secret.yaml").read_text() == SECRET
