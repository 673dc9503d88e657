"""Over-long and non-UTF-8 names of movies, states, scenarios and games are 4xx JSON errors, never 500s (issue 31 item 4)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from starlette.testclient import TestClient

from retrokit import paths
from retrokit.studio.app import create_app
from retrokit.studio.session import Session

DASHER = Path(__file__).resolve().parent.parent / "games" / "Dasher-Genesis"
TOKEN, PORT = "names-token", 8768
NAMES = ["a" * 252, "a" * 300, "%ff%fe", "%25ff", "\udcff", "\ud800x", "a" * 252 + "-Genesis"]
ROUTES = [
    ("POST", "/api/movies/play", "name"),
    ("POST", "/api/movies/stop", "name"),
    ("POST", "/api/states/load", "name"),
    ("POST", "/api/states/save", "name"),
    ("POST", "/api/states/default", "name"),
    ("POST", "/api/play/reset", "state"),
    ("POST", "/api/game", "game"),
    ("PUT", "/api/scenario/draft", "name"),
    ("POST", "/api/scenario/compile", "name"),
    ("POST", "/api/scenario/live", "name"),
]


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    root = tmp_path_factory.mktemp("names")
    shutil.copytree(DASHER, root / "games" / "Dasher-Genesis", ignore=shutil.ignore_patterns("movies"))
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv(paths.GAMES_ENV, str(root / "games"))
        patch.setenv(paths.DATA_ENV, str(root / "data"))
        session = Session("Dasher-Genesis", "Zone1.Act1")
        session.paused = True
        app = create_app(session, token=TOKEN, port=PORT)
        with TestClient(app, base_url=f"http://127.0.0.1:{PORT}", headers={"X-Retrokit-Token": TOKEN},
                        raise_server_exceptions=False) as client:  # fmt: skip
            yield client


@pytest.mark.parametrize("name", NAMES, ids=["252-bytes", "300-bytes", "ff-fe", "double-encoded-ff", "lone-low-surrogate",
                                             "lone-high-surrogate", "long-game-name"])
@pytest.mark.parametrize("method, route, key", ROUTES, ids=[f"{m} {r}" for m, r, _ in ROUTES])
def test_a_hostile_name_is_a_one_line_4xx(client, method, route, key, name):
    body = {key: name, "text": "reward: 0\n"}
    answer = client.request(method, route, content=json.dumps(body), headers={"Content-Type": "application/json"})
    assert 200 <= answer.status_code < 500, answer.text
    if answer.status_code >= 400:
        error = answer.json()
        assert error["kind"].endswith("Error") and "\n" not in error["error"], error


@pytest.mark.parametrize("name", NAMES[:4], ids=["252-bytes", "300-bytes", "ff-fe", "double-encoded-ff"])
def test_a_hostile_scenario_name_in_the_query_is_a_4xx(client, name):
    answer = client.get("/api/scenario", params={"name": name})
    assert 200 <= answer.status_code < 500, answer.text
