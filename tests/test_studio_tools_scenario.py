"""The studio's scenario editor and click to find on a real Dasher session, and hostile requests to every tool.

As tests/test_studio_tools.py: the studio's application through Starlette's
TestClient on a copy of Dasher's folder and a data folder of its own
(tests/studioclient.py), the session paused so only what a test does moves
the game.
"""

from __future__ import annotations

import time
from pathlib import Path

import pytest
import studioclient
from starlette.testclient import TestClient
from studioclient import LIVES, P1_X, fields, ok, open_studio, refused, step

from retrokit.studio.session import Session

data_fixture, game_fixture, client_fixture = studioclient.fixtures()


# --- scenario -----------------------------------------------------------------------------------


BROKEN = "description: a typo\ndefine:\n  gone: p1_lives < initial(p1_lives)\nreward: delta(p1_xx)\ndone: gone\n"


def test_compile_errors_carry_the_line_and_column_the_language_reports(client, game, tmp_path):
    from retrokit.dsl.scenario import load_scenario
    from retrokit.errors import ScenarioCompileError

    result = ok(client.post("/api/scenario/compile", json={"text": BROKEN}))
    path = game.parent / "scenario.yaml"
    (tmp_path / "copy").mkdir()
    file = tmp_path / "copy" / "scenario.yaml"
    file.write_text(BROKEN)
    with pytest.raises(ScenarioCompileError) as raised:
        load_scenario(file, list(fields(client)))
    assert (result["ok"], result["line"], result["column"]) == (False, raised.value.line, raised.value.column) == (
        False, 4, 15)
    assert result["message"] == str(raised.value).replace(str(file), str(path.resolve()))
    assert result["error"] == result["message"].splitlines()[0] and "Did you mean 'p1_x'?" in result["error"]
    syntax = ok(client.post("/api/scenario/compile", json={"text": "reward: (p1_x +\n"}))
    assert (syntax["kind"], syntax["line"], syntax["column"]) == ("ScenarioSyntaxError", 1, 16)
    good = ok(client.post("/api/scenario/compile", json={"text": "reward: delta(p1_x)\n"}))
    assert good == {"ok": True, "name": "scenario", "players": 1, "fields": ["p1_x"]}


def test_editor_text_includes_only_files_of_the_games_folders(client, game, tmp_path):
    (game.parent / "parts.yaml").write_text("define:\n  gain: delta(p1_x)\n")
    good = ok(client.post("/api/scenario/compile", json={"text": "include: [parts.yaml]\nreward: gain\n"}))
    assert good["ok"] and good["fields"] == ["p1_x"]
    secret = tmp_path / "secret.yaml"
    secret.write_text("define:\n  gain: 1\n")
    (game.parent / "link.yaml").symlink_to(secret)
    for name in (str(secret), "../../secret.yaml", "%2e%2e/%2e%2e/secret.yaml", "link.yaml"):
        refused_ = ok(client.post("/api/scenario/compile", json={"text": f"include: [{name!r}]\nreward: 1\n"}))
        assert not refused_["ok"] and "inside the game's folders" in refused_["error"], refused_
        assert (refused_["line"], refused_["column"]) == (1, 11)


def test_the_draft_survives_a_restart_and_only_compiling_text_is_saved(game, data):
    scenario = game.parent / "scenario.yaml"
    saved = scenario.read_text()
    with open_studio(Session("Dasher-Genesis", "Zone1.Act1")) as client:
        assert ok(client.get("/api/scenario"))["draft"] is None
        kept = ok(client.put("/api/scenario/draft", json={"text": BROKEN}))
        assert kept["ok"] is False and kept["line"] == 4 and Path(kept["draft"]).is_relative_to(data)
    with open_studio(Session("Dasher-Genesis", "Zone1.Act1")) as client:  # a new server, as after Ctrl-C
        shown = ok(client.get("/api/scenario"))
        assert shown["text"] == saved and shown["draft"] == BROKEN and shown["writable"]
        error = refused(client.post("/api/scenario/save", json={"text": BROKEN}))
        assert (error["line"], error["column"], error["kind"]) == (4, 15, "ScenarioCompileError")
        assert scenario.read_text() == saved and ok(client.get("/api/scenario"))["draft"] == BROKEN
        fixed = BROKEN.replace("p1_xx", "p1_x")
        assert ok(client.post("/api/scenario/save", json={"text": fixed}))["saved"] == str(scenario.resolve())
        assert scenario.read_text() == fixed
        assert ok(client.get("/api/scenario"))["draft"] is None
        made = ok(client.post("/api/scenario/save", json={"name": "speedrun", "text": "reward: delta(p1_x)\n"}))
        assert made["saved"] == str((game.parent / "speedrun.yaml").resolve())
        assert "speedrun" in ok(client.get("/api/scenario?name=speedrun"))["names"]
        ok(client.put("/api/scenario/draft", json={"name": "speedrun", "text": "reward: 1\n"}))
        assert ok(client.delete("/api/scenario/draft?name=speedrun"))["draft"] is None
        assert ok(client.get("/api/scenario?name=speedrun"))["draft"] is None


def test_live_reward_is_the_scenarios_every_frame(client):
    text = "reward: p1_x - prev(p1_x)\ndone: p1_x >= initial(p1_x) + 40\n"
    live = ok(client.post("/api/scenario/live", json={"text": text}))
    assert live["players"] == 1 and live["total"] == 0 and not live["done"]
    start = fields(client)["p1_x"]["value"]
    step(client, 30, ["RIGHT"])
    report = ok(client.get("/api/scenario/live"))
    moved = fields(client)["p1_x"]["value"] - start
    assert len(report["samples"]) == 30 and report["total"] == sum(s[1] for s in report["samples"]) == moved > 0
    assert [s[0] for s in report["samples"]] == list(range(report["frame"] - 29, report["frame"] + 1))
    step(client, 90, ["RIGHT"])
    report = ok(client.get("/api/scenario/live"))
    assert report["done"] and report["total"] >= 40 and report["samples"][-1][3] is True
    ok(client.post("/api/play/reset", json={"state": "Zone1.Act1"}))  # a state loaded: a new episode
    step(client, 2)
    report = ok(client.get("/api/scenario/live"))
    assert not report["done"] and report["total"] == 0
    assert ok(client.delete("/api/scenario/live")) == {"live": False}
    assert ok(client.get("/api/scenario/live")) == {"live": False}
    error = refused(client.post("/api/scenario/live", json={"text": "reward: nope\n"}))
    assert (error["line"], error["column"]) == (1, 9)


def test_a_scenario_failing_at_run_time_says_where_and_the_game_goes_on(client):
    live = ok(client.post("/api/scenario/live", json={"text": "reward: 1 / (p1_lives - 3)\n"}))
    assert (live["error"]["kind"], live["error"]["line"], live["error"]["column"]) == ("ScenarioRuntimeError", 1, 9)
    assert "division by zero" in live["error"]["error"] and "\n" not in live["error"]["error"]
    frame = ok(client.get("/api/status"))["frame"]
    step(client, 3)
    assert ok(client.get("/api/status"))["frame"] == frame + 3
    assert ok(client.get("/api/scenario/live"))["error"]["kind"] == "ScenarioRuntimeError"


def test_the_games_own_scenario_goes_live_by_name(client):
    live = ok(client.post("/api/scenario/live", json={}))
    assert live["name"] == "scenario" and live["players"] == 2
    step(client, 10, ["RIGHT"])
    assert ok(client.get("/api/scenario/live"))["total"] > 0
    refused(client.post("/api/scenario/live", json={"name": "nosuch"}), 404)


# --- click to find ------------------------------------------------------------------------------


def run_job(client: TestClient, body: dict, timeout: float = 300.0) -> dict:
    ok(client.post("/api/clickfind", json=body))
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        job = ok(client.get("/api/clickfind"))
        if job["finished"]:
            return job
        time.sleep(0.05)
    raise AssertionError(f"click to find did not finish in {timeout} s: {job}")


def future(session: Session) -> tuple[bytes, bytes]:
    """The RAM and the screen 10 frames from now (run on a copy of the state: the game stays where it is)."""
    emulator = session.search.emulator
    now = emulator.get_state()
    emulator.run(0, 10)
    seen = session.search.layout.read(emulator.space).tobytes(), emulator.screen().tobytes()
    emulator.set_state(now)
    return seen


SPAWN_BLINK = 70  # frames: a player blinks for its first 60 (tools/testcart/src/player.c SPAWN_INVULN)


def test_click_on_the_player_finds_its_position_without_disturbing_the_game(client):
    step(client, SPAWN_BLINK)
    values = fields(client)
    assert values["p1_invuln"]["value"] == 0
    x, y = values["p1_x"]["value"] - values["camera_x"]["value"], values["p1_y"]["value"] - 8  # the sprite's middle
    session = client.app.state.session
    before = session.call_blocking(future)
    job = run_job(client, {"x": x, "y": y, "region": {"start": "0xFF0020", "length": 32}})
    assert job["done"] == job["total"] == 32 and not job["error"]
    found = {hit["address"]: hit for hit in job["hits"]}
    assert P1_X in found and found[P1_X]["fields"] == ["p1_x"]  # its high byte moves it off the point
    assert LIVES not in found  # the HUD's lives are drawn elsewhere
    assert session.call_blocking(future) == before  # the game is where it was, and goes on the same


def screen(client: TestClient):
    import io

    import numpy as np
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(client.get("/api/screen.png").content)).convert("RGB"))


def test_click_on_the_hud_finds_lives_among_the_candidates(client):
    import numpy as np

    step(client, SPAWN_BLINK + 2)
    shown = screen(client)
    ok(client.post("/api/play/reset", json={"state": "Zone1.Act1"}))
    step(client, SPAWN_BLINK)
    ok(client.post("/api/search/poke", json={"address": LIVES, "value": 4}))  # as the job's first try will
    step(client, 2)
    y, x = np.argwhere((screen(client) != shown).any(axis=-1))[0]  # a pixel where the HUD's 3 and 4 differ
    ok(client.post("/api/play/reset", json={"state": "Zone1.Act1"}))
    step(client, SPAWN_BLINK)
    ok(client.post("/api/search/new", json={"types": ["|u1"]}))
    ok(client.post("/api/search/filter", json={"op": "equal", "value": 3}))
    job = run_job(client, {"x": int(x), "y": int(y), "region": "candidates"})
    assert job["total"] == ok(client.get("/api/search"))["count"] and not job["error"]
    assert LIVES in {hit["address"] for hit in job["hits"]}
    assert next(h for h in job["hits"] if h["address"] == LIVES)["fields"] == ["p1_lives"]


def test_a_job_is_capped_and_cancelled(client):
    big = refused(client.post("/api/clickfind", json={"x": 10, "y": 10, "region": {"start": "0xFF0000",
                                                                                      "length": 65536}}))
    assert "at most 8,192 cells" in big["error"]
    refused(client.post("/api/clickfind", json={"x": 400, "y": 10, "region": {"start": "0xFF0000"}}))
    refused(client.post("/api/clickfind", json={"x": 10, "y": 10, "region": {"start": "0x10", "length": 4}}))
    refused(client.post("/api/clickfind", json={"x": 10, "y": 10, "region": "everything"}))
    ok(client.post("/api/clickfind", json={"x": 10, "y": 10, "region": {"start": "0xFF0000", "length": 8192}}))
    cancelled = ok(client.post("/api/clickfind/cancel"))
    assert cancelled["cancelled"] and cancelled["finished"]
    time.sleep(0.2)
    job = ok(client.get("/api/clickfind"))
    assert job["done"] < job["total"] == 8192


# --- hostile input ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("method", "url", "body", "status"),
    [
        ("post", "/api/search/filter", {"op": 3}, 400),
        ("post", "/api/search/filter", {"op": "equal", "value": "three"}, 400),
        ("post", "/api/search/filter", {"op": "equal", "value": 3, "than": "previous"}, 400),
        ("post", "/api/search/filter", {"op": "equal", "than": ["x"]}, 400),
        ("post", "/api/search/filter", {"op": "greater", "than": "0xFFFFFFFFFF"}, 400),
        ("post", "/api/search/new", {"types": ["|q7"]}, 400),
        ("post", "/api/search/snapshot", {"label": "x" * 1000}, 400),
        ("get", "/api/search/candidates?limit=0", None, 400),
        ("get", "/api/search/candidates?limit=101", None, 400),
        ("get", "/api/search/candidates?limit=99999999999999999999", None, 400),
        ("post", "/api/search/poke", {"address": "0xFF002B", "value": 300}, 400),
        ("post", "/api/search/poke", {"address": -1, "value": 1}, 400),
        ("post", "/api/search/poke", {"address": "0xFF002B", "value": 1, "type": "|zz"}, 400),
        ("post", "/api/search/field", {"name": "9lives", "address": LIVES, "type": "|u1"}, 400),
        ("post", "/api/search/field", {"name": "ok", "address": LIVES, "type": "|u1", "range": [0, 1, 2]}, 400),
        ("patch", "/api/fields/p1_lives", {}, 400),
        ("post", "/api/scenario/compile", {"text": 7}, 400),
        ("post", "/api/scenario/compile", {"name": "../../etc/passwd", "text": "reward: 1"}, 400),
        ("put", "/api/scenario/draft", {"name": "a/b", "text": "reward: 1"}, 400),
        ("post", "/api/scenario/save", {"text": "reward: [1\n"}, 400),
        ("post", "/api/scenario/save", {"text": "&a [*a]"}, 400),
        ("get", "/api/scenario?name=..", None, 400),
        ("post", "/api/clickfind", {"x": "left", "y": 0}, 400),
        ("post", "/api/clickfind", {"x": 1, "y": 1, "frames": 1000}, 400),
        ("get", "/api/clickfind", None, 400),
        ("get", "/api/ram?start=nowhere", None, 400),
        ("post", "/api/ram/watch", {"start": "0xFF0000", "length": -5}, 400),
    ],
    ids=lambda v: v if isinstance(v, str) else None,
)
def test_hostile_requests_get_one_line_json_errors(client, method, url, body, status):
    response = getattr(client, method)(url, **({} if body is None else {"json": body}))
    refused(response, status)


def test_a_body_that_is_not_json_or_too_big_is_refused(client):
    lone = b'{"text": "reward: 1 # \\ud800"}'  # JSON may carry half a UTF-16 pair; no file can hold it
    for route in ("/api/scenario/compile", "/api/scenario/save", "/api/scenario/live"):
        assert "UTF-16" in refused(client.post(route, content=lone))["error"]
    assert "UTF-16" in refused(client.put("/api/scenario/draft", content=lone))["error"]
    refused(client.post("/api/search/filter", content=b"{not json", headers={"Content-Type": "application/json"}))
    refused(client.post("/api/search/filter", content=b"[1, 2]"))
    huge = "reward: " + "1 + " * 400_000 + "1\n"
    assert client.post("/api/scenario/compile", json={"text": huge}).status_code == 413
    started = time.monotonic()
    deep = ok(client.post("/api/scenario/compile", json={"text": "reward: " + "(" * 400_000 + "1" + ")" * 400_000}))
    assert deep["ok"] is False and (deep["line"], deep["column"]) == (1, 1009) and "brackets" in deep["error"]
    assert time.monotonic() - started < 30  # lark alone took minutes over so many
