"""The studio's tools (RAM search, watch, RAM view) on a real Dasher session (tests/studioclient.py).

Each test runs the studio's application through Starlette's TestClient on a
copy of Dasher's folder (anything written lands there) and a data folder of
its own, with the session paused so that only what a test does moves the game.
"""

from __future__ import annotations

import re

import pytest
import studioclient
from studioclient import LIVES, P1_X, PORT, TOKEN, fields, ok, refused, step

data_fixture, game_fixture, client_fixture = studioclient.fixtures()


# --- RAM search -----------------------------------------------------------------------------------


def test_search_finds_lives_and_adds_it_as_a_field(client, game):
    ok(client.post("/api/search/new"))
    threes = ok(client.post("/api/search/filter", json={"op": "equal", "value": 3}))["count"]
    ok(client.post("/api/search/poke", json={"address": "0xFF002B", "value": 2}))  # a life lost
    ok(client.post("/api/search/snapshot", json={"label": "a life lost"}))
    found = ok(client.post("/api/search/filter", json={"op": "decreased"}))
    assert found["filter"] == "decreased --than previous" and found["snapshots"][-1] == "a life lost"
    assert found["before"] == threes > found["count"]
    rows = ok(client.get("/api/search/candidates?limit=50"))["rows"]
    lives = next(r for r in rows if r["address"] == LIVES and r["type"] == "|u1")
    assert lives["values"] == [3, 2] and lives["value"] == 2 and lives["hex"] == "0xFF002B"
    assert "|i1" in lives["also"]  # the types that read the same byte alike are one row

    undone = ok(client.post("/api/search/undo"))
    assert undone["undone"] == "decreased --than previous" and undone["count"] == threes and undone["can_redo"]
    assert ok(client.post("/api/search/redo"))["count"] == found["count"]
    refused(client.post("/api/search/redo"))  # nothing left to redo

    added = ok(client.post("/api/search/field", json={"name": "lives_found", "address": LIVES, "type": "|u1",
                                                       "range": [0, 9]}))
    assert added["path"] == str(game.resolve()) and added["range"] == [0, 9]
    assert re.search(r'\n  lives_found: +\{address: 0xFF002B, type: "\|u1", range: \[0, 9\]\}\n', game.read_text())
    assert fields(client)["lives_found"]["value"] == 2  # the session reads the new field at once
    again = refused(client.post("/api/search/field", json={"name": "lives_found", "address": LIVES, "type": "|u1"}),
                    409)
    assert again["kind"] == "FileConflictError"


def test_filters_take_every_form_of_than_and_scales(client):
    ok(client.post("/api/search/new", json={"types": ["|u1", ">u2"]}))
    scaled = ok(client.post("/api/search/filter", json={"op": "equal", "value": 30}))  # 3 lives, shown x10
    rows = ok(client.get("/api/search/candidates?limit=100"))["rows"]
    assert any(r["address"] == LIVES and "x10" in r["scales"] for r in rows), scaled
    ok(client.post("/api/search/new", json={"types": ["|u1"]}))
    step(client, 20, ["RIGHT"])
    ok(client.post("/api/search/snapshot"))
    step(client, 20, ["RIGHT"])
    ok(client.post("/api/search/snapshot"))
    status = ok(client.get("/api/search"))
    assert len(status["snapshots"]) == 3 and status["types"] == ["|u1"]
    for than in ("first", 0, "1", "previous"):
        ok(client.post("/api/search/filter", json={"op": "increased", "than": than}))
    ok(client.post("/api/search/filter", json={"op": "greater", "value": 1, "than": "changes"}))
    ok(client.post("/api/search/filter", json={"op": "not-equal", "than": "0xFF0004"}))
    rows = ok(client.get("/api/search/candidates"))["rows"]
    assert P1_X + 1 in {r["address"] for r in rows}  # the player's x ran right twice
    bad = refused(client.post("/api/search/filter", json={"op": "changed", "than": "prevous"}))
    assert "Did you mean 'previous'?" in bad["error"]
    refused(client.post("/api/search/filter", json={"op": "increased", "than": "7"}))  # no snapshot 7


def test_a_search_takes_at_most_64_snapshots(client):
    from retrokit.studio.search import MAX_SNAPSHOTS

    ok(client.post("/api/search/new"))
    for _ in range(MAX_SNAPSHOTS - 1):
        ok(client.post("/api/search/snapshot"))
    full = refused(client.post("/api/search/snapshot"))
    assert "at most 64 snapshots" in full["error"] and full["kind"] == "RamSearchError"
    no_room = refused(client.post("/api/search/find", json={"changes": "RIGHT", "keeps": "_"}))
    assert "Expected room for two snapshots a round; this search has 64 of its 64" in no_room["error"]
    assert len(ok(client.post("/api/search/new"))["snapshots"]) == 1


def test_find_plays_scripts_with_repeats_and_finds_the_lives(client, game):
    """The studio's scripts are the one script language: repeats, as ramsearch and state recipes take them."""
    ok(client.post("/api/search/new"))
    frame = ok(client.get("/api/status"))["frame"]
    found = ok(client.post("/api/search/find", json={
        "changes": "(RIGHT*100)*2", "keeps": "(_*65)*2", "kind": "decreases", "name": "lives_again", "save": True}))
    assert found["found"] and (found["rows"][0]["address"], found["rows"][0]["type"]) == (LIVES, "|u1")
    assert found["steps"][0].startswith("script (RIGHT*100)*2 (200 frames); decreased --than previous: ")
    assert found["field"]["name"] == "lives_again" and "lives_again:" in game.read_text()
    assert ok(client.get("/api/status"))["frame"] == frame + found["frames"] == frame + 3 * 200 + 2 * 130


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ({"keeps": "_*5"}, "Expected 'changes' in the request's JSON object"),
        ({"changes": ["RIGHT"], "keeps": "_*5"}, "Expected 'changes' to be a string"),
        ({"changes": "RIGHT*5", "keeps": "_*5", "kind": "becomes"}, "Expected a number with 'becomes'"),
        ({"changes": "RIGHT*5", "keeps": "_*5", "kind": "decrease"}, "Did you mean 'decreases'?"),
        ({"changes": "RIGHT*5", "keeps": "_*5", "kind": "becomes", "value": "x"}, "the number it becomes"),
        ({"changes": "RIGHT*5", "keeps": "((A*9999)*99999)*99999"}, "at most 1,000,000 frames"),
        ({"changes": "RIGHT*30000", "keeps": "_*6001"}, "at most 36,000 frames together in the studio; got 36,001"),
        ({"changes": "(RIGHT*2", "keeps": "_*5"}, "In the script at line 1, column 8: Expected"),
        ({"changes": "RIHGT", "keeps": "_*5"}, "Did you mean 'RIGHT'?"),
        ({"changes": "RIGHT*5", "keeps": "_*5", "save": True}, "Expected 'name' in the request's JSON object"),
        ({"changes": "RIGHT*5", "keeps": "_*5", "save": True, "name": "2lives"}, "field name"),
    ],
    ids=["no-changes", "changes-not-text", "becomes-no-number", "kind-typo", "number-not-a-number", "hostile-script",
         "over-the-studio-budget", "script-syntax", "button-typo", "save-without-name", "bad-name"],
)  # fmt: skip
def test_find_refuses_a_bad_request_before_the_game_moves(client, body, message):
    ok(client.post("/api/search/new"))
    frame = ok(client.get("/api/status"))["frame"]
    answer = client.post("/api/search/find", json=body)
    assert answer.status_code == 400 and message in answer.json()["error"], answer.text
    assert ok(client.get("/api/status"))["frame"] == frame and len(ok(client.get("/api/search"))["snapshots"]) == 1


def test_the_longest_listing_stays_in_bounded_memory(game):
    from childproc import MAX_RSS_MB, run_child

    child = run_child(
        f"""
        from starlette.testclient import TestClient
        from retrokit.studio.app import create_app
        from retrokit.studio.session import Session

        session = Session("Dasher-Genesis", "Zone1.Act1")
        session.paused = True
        app = create_app(session, token="{TOKEN}", port={PORT})
        with TestClient(app, base_url="http://127.0.0.1:{PORT}", headers={{"X-Retrokit-Token": "{TOKEN}"}}) as client:
            client.post("/api/play/buttons", json={{"buttons": ["RIGHT"]}})
            for _ in range(63):  # a fresh search: every type at every address, with a value at each snapshot
                client.post("/api/play/step", json={{"frames": 1}})
                assert client.post("/api/search/snapshot").status_code == 200
            rows = client.get("/api/search/candidates?limit=100").json()["rows"]
            print(len(rows), len(rows[0]["values"]))
        """,
        timeout=300,
    )
    assert child.returncode == 0 and child.stdout.split() == ["100", "64"], child.describe()
    assert child.peak_rss_mb < MAX_RSS_MB, child.describe()


def test_candidate_values_are_pushed_live_over_the_socket(client):
    ok(client.post("/api/search/new", json={"types": ["|u1"]}))
    ok(client.post("/api/search/filter", json={"op": "equal", "value": 3}))
    assert any(r["address"] == LIVES for r in ok(client.get("/api/search/candidates?limit=100"))["rows"])
    ok(client.post("/api/search/poke", json={"address": LIVES, "value": 7}))
    url = f"ws://127.0.0.1:{PORT}/ws?token={TOKEN}"
    with client.websocket_connect(url, headers={"Origin": f"http://127.0.0.1:{PORT}"}) as ws:
        ok(client.post("/api/play/step", json={"frames": 6}))
        values = None
        for _ in range(200):
            message = ws.receive()
            if message.get("text") and '"candidates"' in message["text"]:
                import json

                values = {(a, t): v for a, t, v in json.loads(message["text"])["values"]}
                break
        assert values is not None and values[(LIVES, "|u1")] == 7


# --- watch and field edits ----------------------------------------------------------------------


def test_watch_lists_every_field_with_its_value_as_the_env_reads_it(client):
    import retrokit

    rows = fields(client)
    env = retrokit.make("Dasher-Genesis", "Zone1.Act1")
    try:
        _, info = env.reset()
    finally:
        env.close()
    assert set(rows) == set(info) - {"rewards", "dones"}
    assert rows["p1_lives"]["value"] == 3 and rows["p1_lives"]["range"] == [0, 9]
    assert rows["p1_x"] == {**rows["p1_x"], "hex": "0xFF0020", "type": ">i2", "value": info["p1_x"]}


def test_a_field_is_edited_in_place_and_the_session_reads_it_again(client, game):
    before = game.read_text().splitlines()
    edited = ok(client.patch("/api/fields/p1_lives", json={"range": [0, 5]}))
    assert edited["range"] == [0, 5] and edited["type"] == "|u1"
    ok(client.patch("/api/fields/ring_count", json={"address": "0xFF00C2", "type": "|i1"}))
    after = game.read_text().splitlines()
    changed = sorted(b for a, b in zip(before, after) if a != b)
    assert len(before) == len(after) and len(changed) == 2, changed
    assert changed[0] == '  p1_lives:    {address: 0xFF002B, type: "|u1", range: [0, 5]}'
    assert changed[1].startswith('  ring_count:  {address: 0xFF00C2, type: "|i1"}')
    rows = fields(client)
    assert rows["p1_lives"]["range"] == [0, 5] and rows["ring_count"]["hex"] == "0xFF00C2"
    ok(client.patch("/api/fields/game_mode", json={"range": [0, 4]}))  # its comment stays
    assert '  game_mode:   {address: 0xFF0002, type: "|u1", range: [0, 4]}   # 0 title, 1 play, 2 act clear' in (
        game.read_text())
    ok(client.patch("/api/fields/p1_lives", json={"range": None}))  # a range can be dropped
    assert "range" not in next(line for line in game.read_text().splitlines() if "p1_lives:" in line)

    text = game.read_text()
    unknown = refused(client.patch("/api/fields/p1_livs", json={"range": [0, 9]}), 404)
    assert "Did you mean 'p1_lives'?" in unknown["error"]
    refused(client.patch("/api/fields/p1_lives", json={"range": [9, 0]}))
    refused(client.patch("/api/fields/p1_lives", json={"type": "|x9"}))
    refused(client.patch("/api/fields/p1_lives", json={"address": "0x10"}))  # outside RAM
    refused(client.patch("/api/fields/p1_lives", json={"colour": "red"}))
    assert game.read_text() == text  # a refused edit writes nothing


# --- RAM view -----------------------------------------------------------------------------------


def test_ram_view_marks_what_changed_since_the_last_frame_and_a_snapshot(client):
    ok(client.post("/api/search/new"))  # snapshot 0: now
    view = ok(client.post("/api/ram/watch", json={"start": "0xFF0000", "length": 64, "snapshot": 0}))
    assert view["hex"] == "0xFF0000" and len(view["values"]) == 64 and view["differs"] == []
    ok(client.post("/api/search/poke", json={"address": "0xFF0030", "value": 99}))
    step(client, 1)
    view = ok(client.get("/api/ram?start=0xFF0000&length=64&snapshot=0"))
    assert 7 in view["changed"]  # the frame counter's low byte (0xFF0004, >u4) changes every frame
    assert {7, 0x30} <= set(view["differs"]) and view["values"][0x30] == 99
    ok(client.delete("/api/ram/watch"))
    refused(client.get("/api/ram?start=0xFF0000&length=100000"))
    refused(client.get("/api/ram?start=0x10&length=4"))
    refused(client.get("/api/ram?start=0xFF0000&length=4&snapshot=9"))


def test_add_field_on_a_shipped_game_writes_its_copy_in_the_data_folder(tmp_path, monkeypatch):
    """Issue 42: the studio's Add field on the checkout's Dasher (its default game) wrote the tracked game.yaml."""
    from retrokit import paths
    from retrokit.data.games import find_game
    from retrokit.studio.session import Session

    shipped = (studioclient.DASHER / "game.yaml").read_bytes()
    monkeypatch.delenv(paths.GAMES_ENV, raising=False)
    monkeypatch.setenv(paths.DATA_ENV, str(tmp_path))
    with studioclient.open_studio(Session("Dasher-Genesis", "Zone1.Act1")) as client:
        added = ok(client.post("/api/search/field", json={"name": "lives_found", "address": LIVES, "type": "|u1"}))
        assert fields(client)["lives_found"]["value"] == 3  # the session reads it from the copy at once
    copy = tmp_path / "games" / "Dasher-Genesis" / "game.yaml"
    assert added["path"] == str(copy) and "lives_found" in find_game("Dasher-Genesis").fields
    assert (studioclient.DASHER / "game.yaml").read_bytes() == shipped
