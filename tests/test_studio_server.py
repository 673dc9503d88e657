"""The studio's core on a real Dasher session: play over HTTP and the WebSocket, states, movies, faults.

The session plays a copy of Dasher's folder in tmp_path, opened by its path,
so the states and movies it writes land in that copy (a game opened by its
folder keeps its made states next to its game.yaml).
"""

from __future__ import annotations

import asyncio
import json
import os
import struct
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from dashercopy import dasher_copy
from starlette.testclient import TestClient

from retrokit.host.systems import all_systems, get_system
from retrokit.movie import read_bk2
from retrokit.studio.app import SCREEN_HEADER, create_app
from retrokit.studio.play import key_map, pad_map
from retrokit.studio.push import Screen, Subscriber
from retrokit.studio.session import Session

REPO = Path(__file__).resolve().parent.parent
DASHER = REPO / "games" / "Dasher-Genesis"
TOKEN = "test-token"
PORT = 8722
BASE = f"http://127.0.0.1:{PORT}"
RIGHT = 1 << 7  # the RetroPad bit of RIGHT


@pytest.fixture(scope="module")
def studio_game(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The session's copy of Dasher: the states the tests play, and the one solution movie they replay.

    The validation below then checks 5 states and 1 movie, not Dasher's 9 states and 6 movies (5,700 frames of
    replay); tests/test_validate.py validates Dasher as shipped.
    """
    states = ("Zone1.Act1", "Zone1.Act1.2P", "Zone1.Act2", "Zone2.Act1", "Zone3.Act1")
    return dasher_copy(tmp_path_factory.mktemp("studio"), states, movies=("Zone1.Act1",))


@pytest.fixture(scope="module")
def client(studio_session: Session):
    app = create_app(studio_session, token=TOKEN, port=PORT)
    with TestClient(app, base_url=BASE, headers={"X-Retrokit-Token": TOKEN}) as client:
        yield client


def post(client: TestClient, route: str, body: dict | None = None, status: int = 200) -> dict:
    answer = client.post(route, json=body or {})
    assert answer.status_code == status, answer.text
    return answer.json()


def ram(session: Session) -> np.ndarray:
    return session.call_blocking(lambda s: s.search.emulator.ram.copy())


def paused_at(client: TestClient, state: str = "Zone1.Act1") -> None:
    post(client, "/api/play/pause")
    post(client, "/api/play/reset", {"state": state})
    post(client, "/api/play/buttons", {"buttons": []})


def socket(client: TestClient):
    return client.websocket_connect(f"ws://127.0.0.1:{PORT}/ws?token={TOKEN}")


def next_message(ws, kind: str) -> dict:
    """Read the socket (screens and other messages go by, as on a page) until a JSON message of this type."""
    while True:
        message = ws.receive()
        if message.get("text") and json.loads(message["text"])["type"] == kind:
            return json.loads(message["text"])


def receive_screen(ws) -> tuple[tuple, bytes]:
    while True:
        message = ws.receive()
        if message.get("bytes"):
            return SCREEN_HEADER.unpack_from(message["bytes"]), message["bytes"]


# --- play -------------------------------------------------------------------------------------------------


def test_info_lists_the_systems_buttons_and_the_default_keys(client):
    info = client.get("/api/info").json()
    assert info["game"] == "Dasher-Genesis" and info["system"] == "Genesis"
    assert set(info["buttons"]) == {"B", "A", "MODE", "START", "UP", "DOWN", "LEFT", "RIGHT", "C", "Y", "X", "Z"}
    keys = info["keys"]
    assert keys["ArrowUp"] == "UP" and keys["ArrowDown"] == "DOWN" and keys["ArrowLeft"] == "LEFT"
    assert keys["ArrowRight"] == "RIGHT" and keys["Enter"] == "START"
    assert set(keys.values()) == set(info["buttons"])  # every button has a key
    assert info["gamepad"]["12"] == "UP" and info["gamepad"]["9"] == "START"
    assert info["ram"] == {"start": 0xFF0000, "length": 256, "digits": 6}
    assert (info["width"], info["height"]) == (320, 224) and 59 < info["frame_rate"] < 61
    assert "Zone1.Act1" in info["states"] and info["speeds"] == [0.25, 8.0]


SYSTEMS = sorted(all_systems())


@pytest.mark.parametrize("system", SYSTEMS)
def test_every_system_has_a_key_for_every_button(system):
    desc = get_system(system)
    keys = key_map(desc)
    assert set(keys.values()) == set(desc.button_names)  # one key each, none left out
    for key, button in (("ArrowUp", "UP"), ("ArrowDown", "DOWN"), ("ArrowLeft", "LEFT"), ("ArrowRight", "RIGHT"),
                        ("Enter", "START")):
        assert keys.get(key) == button or button not in desc.button_names
    assert set(pad_map(desc).values()) <= set(desc.button_names)


def test_the_socket_sends_screens_with_the_documented_header(client, studio_session):
    post(client, "/api/play/resume")
    with socket(client) as ws:
        (magic, width, height, frame, depth), data = receive_screen(ws)
        assert magic == b"RKS1" and (width, height, depth) == (320, 224, 3)
        assert len(data) == SCREEN_HEADER.size + width * height * depth == 16 + 320 * 224 * 3
        (_, _, _, later, _), _ = receive_screen(ws)
        assert later > frame  # the game runs: each screen is a newer frame
        pixels = np.frombuffer(data, np.uint8, offset=16).reshape(height, width, 3)
        assert pixels.std() > 0  # a picture, not a blank


@pytest.mark.parametrize(("query", "acked"), [("&ack=1", 0), ("&ack=0", None), ("", None)], ids=["ack", "no-ack", "unsaid"])
def test_a_page_that_says_it_acknowledges_is_held_to_the_window_from_its_first_message(
    client, studio_session, query, acked
):
    """``/ws?ack=1`` (the studio's page) is windowed from the start, not from its first ack, which a loaded
    machine read after a backlog of screens had gone out; a page that does not say so is never held back."""
    paused_at(client)
    with client.websocket_connect(f"ws://127.0.0.1:{PORT}/ws?token={TOKEN}{query}") as ws:
        ws.receive()  # it has subscribed
        [page] = studio_session._subscribers
        assert page.acked == acked


def test_a_bad_ack_parameter_is_a_clear_error_and_the_socket_closes(client):
    with client.websocket_connect(f"ws://127.0.0.1:{PORT}/ws?token={TOKEN}&ack=yes") as ws:
        error = json.loads(ws.receive_text())
        assert error["kind"] == "InvalidArgumentError" and "Expected ack=1" in error["error"], error
        assert ws.receive()["type"] == "websocket.close"


class RecordingPage(Subscriber):
    """A page that notes the frame of every screen offered to it (its loop never runs: nothing is sent)."""

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        super().__init__(loop)
        self.frames: list[int] = []

    def offer_screen(self, screen: Screen) -> None:
        self.frames.append(screen.frame)
        super().offer_screen(screen)


def test_a_page_that_comes_as_a_frame_ends_gets_that_frame_once(client, studio_session):
    """A frame that ends between a page's arrival and its first-screen job is offered to it once, not twice.

    A job holds the emulator thread while the page comes, then plays one frame, as the running loop's next
    tick does when it falls there (the socket test above then saw the same frame twice, 1 run in 9 under load).
    """
    paused_at(client)
    holding, arrived = threading.Event(), threading.Event()

    def frame_after_arrival(s: Session) -> None:
        holding.set()
        arrived.wait()
        s.advance(1)

    loop = asyncio.new_event_loop()
    page = RecordingPage(loop)
    helper = threading.Thread(target=studio_session.call_blocking, args=(frame_after_arrival,))
    helper.start()
    try:
        holding.wait()
        studio_session.subscribe(page)  # its first-screen job waits behind the frame
        arrived.set()
        helper.join()
        frame = studio_session.call_blocking(lambda s: s.frame)  # after the first-screen job
    finally:
        arrived.set()
        studio_session.unsubscribe(page)
        loop.close()
    assert page.frames == [frame]


def test_the_frame_loop_keeps_to_the_speed_asked(client, studio_session):
    """Never faster than asked (whatever the load); at 8x, faster than at 1x."""
    counts, allowed = {}, {}
    for speed in (0.25, 1, 8):
        post(client, "/api/play/speed", {"value": speed})
        post(client, "/api/play/resume")
        start, began = studio_session.frame, time.monotonic()
        time.sleep(0.5)  # the time measured: a loaded machine's longer sleep allows the frames it played
        counts[speed], allowed[speed] = studio_session.frame - start, speed * 60 * (time.monotonic() - began) + 4
    post(client, "/api/play/pause")
    post(client, "/api/play/speed", {"value": 1})
    assert 0 < counts[0.25] <= allowed[0.25], (counts, allowed)
    assert 0 < counts[1] <= allowed[1], (counts, allowed)
    assert counts[8] > counts[1]


def test_pause_then_step_runs_exactly_the_frames_asked_with_the_buttons_held(client, studio_session):
    paused_at(client)
    before = post(client, "/api/play/step", {"frames": 1})["frame"]
    time.sleep(0.2)
    assert studio_session.frame == before  # paused: nothing moves
    x = ram(studio_session)
    post(client, "/api/play/buttons", {"buttons": ["RIGHT"]})
    status = post(client, "/api/play/step", {"frames": 30})
    assert status["paused"] and status["frame"] == before + 30
    assert (ram(studio_session) != x).any()
    movie = studio_session.call_blocking(lambda s: s.search.movie())
    assert movie.frames[-30:] == [(RIGHT, 0)] * 30  # what was held is what the session recorded


def test_reset_puts_the_game_back_in_the_state(client, studio_session):
    paused_at(client)
    fresh = ram(studio_session)
    post(client, "/api/play/buttons", {"buttons": ["RIGHT"]})
    post(client, "/api/play/step", {"frames": 20})
    assert (ram(studio_session) != fresh).any()
    post(client, "/api/play/reset", {})  # the state the session began from
    assert (ram(studio_session) == fresh).all()


def test_the_socket_takes_the_same_commands(client, studio_session):
    paused_at(client)
    with socket(client) as ws:
        start = studio_session.frame
        ws.send_text(json.dumps({"type": "buttons", "buttons": ["RIGHT", "B"]}))
        ws.send_text(json.dumps({"type": "step", "frames": 5}))
        ws.send_text(json.dumps({"type": "speed", "value": 2}))
        ws.send_text(json.dumps({"type": "status"}))
        status = None
        while status is None or status["speed"] != 2:
            message = ws.receive()
            if message.get("text"):
                status = json.loads(message["text"])
        assert status["type"] == "status" and status["paused"] and status["frame"] == start + 5
        assert studio_session.buttons == ("RIGHT", "B")
        ws.send_text(json.dumps({"type": "speed", "value": "fast"}))
        ws.send_text("not json")
        assert next_message(ws, "error")["kind"] == "InvalidArgumentError"
    post(client, "/api/play/speed", {"value": 1})


def test_tools_hook_frames_and_publish_to_the_page(client, studio_session):
    paused_at(client)
    seen = []

    def hook(s: Session) -> None:
        seen.append(s.frame)
        s.publish({"type": "probe", "frame": s.frame})

    remove = studio_session.on_frame(hook)
    try:
        with socket(client) as ws:
            post(client, "/api/play/step", {"frames": 3})
            probe = next_message(ws, "probe")
        assert seen == [seen[0], seen[0] + 1, seen[0] + 2] and probe["frame"] in seen
    finally:
        remove()


def test_a_failing_hook_is_removed_and_reported_while_the_game_plays_on(client, studio_session):
    paused_at(client)

    def broken(_s: Session) -> None:
        raise ZeroDivisionError("boom")

    studio_session.on_frame(broken)
    with socket(client) as ws:
        post(client, "/api/play/step", {"frames": 2})
        error = next_message(ws, "error")
    assert "ZeroDivisionError: boom" in error["error"]
    assert post(client, "/api/play/step", {"frames": 2})["paused"]  # the loop lives on


def test_closing_the_last_socket_pauses_and_then_stops_the_emulator(client, studio_session):
    post(client, "/api/play/resume")
    with socket(client) as ws:
        receive_screen(ws)
        assert studio_session.running and not studio_session.paused
    deadline = time.monotonic() + 120  # generous: a loaded machine is slow, never wrong
    while studio_session.running and time.monotonic() < deadline:
        time.sleep(0.05)
    assert studio_session.paused and not studio_session.running  # paused at once, thread gone after the grace period
    frame = studio_session.frame
    time.sleep(0.2)
    assert studio_session.frame == frame
    with socket(client) as ws:  # a new tab starts it again, where it was
        receive_screen(ws)
        assert studio_session.running


# --- states -------------------------------------------------------------------------------------------------


def test_save_a_state_with_its_record_list_load_and_make_it_the_default(client, studio_session, studio_game):
    from retrokit.data.states import read_state_file

    paused_at(client)
    post(client, "/api/play/buttons", {"buttons": ["RIGHT"]})
    post(client, "/api/play/step", {"frames": 40})
    saved_ram = ram(studio_session)
    answer = post(client, "/api/states/save", {"name": "Mine"})
    assert answer["status"] == "made" and Path(answer["path"]) == studio_game / "Mine.state"
    assert read_state_file(studio_game / "Mine.state").record is not None  # the record integrate writes
    assert "Mine" in client.get("/api/states").json()["states"]
    post(client, "/api/play/step", {"frames": 10})
    conflict = post(client, "/api/states/save", {"name": "Mine"}, status=409)
    assert conflict["kind"] == "FileConflictError" and "force" in conflict["error"]
    post(client, "/api/states/load", {"name": "Mine"})
    assert (ram(studio_session) == saved_ram).all()
    assert post(client, "/api/states/save", {"name": "Mine"})["status"] == "up to date"
    post(client, "/api/play/step", {"frames": 10})
    assert post(client, "/api/states/save", {"name": "Mine", "force": True})["status"] == "replaced"
    listing = post(client, "/api/states/default", {"name": "Mine"})
    assert listing["default"] == "Mine" and "default: Mine" in (studio_game / "game.yaml").read_text()


def test_a_bad_state_name_or_an_unknown_state_is_a_json_error(client):
    bad = post(client, "/api/states/save", {"name": "a/../../escape"}, status=400)
    assert bad["kind"] == "InvalidArgumentError" and "path separator" in bad["error"]
    unknown = post(client, "/api/states/load", {"name": "Zone1.Act9"}, status=404)
    assert unknown["kind"] == "StateNotFoundError" and "Zone1.Act1" in unknown["error"]
    post(client, "/api/states/default", {"name": "Nope"}, status=404)


def test_a_corrupt_state_is_a_json_error_and_the_server_lives_on(client, studio_session, studio_game, corrupt_state):
    from retrokit.data.states import write_state

    write_state(studio_game / "Broken.state", corrupt_state)
    studio_session.call_blocking(lambda s: s.refresh_game())
    paused_at(client)
    before = ram(studio_session)
    answer = post(client, "/api/states/load", {"name": "Broken"}, status=400)
    assert answer["kind"] == "StateError"
    assert (ram(studio_session) == before).all()  # the game is where it was
    assert post(client, "/api/play/step", {"frames": 2})["paused"]


# --- movies ------------------------------------------------------------------------------------------------


def test_record_a_movie_of_what_is_played_and_replay_it(client, studio_session, studio_game):
    paused_at(client, "Zone1.Act2")
    post(client, "/api/movies/record")
    post(client, "/api/play/buttons", {"buttons": ["RIGHT"]})
    post(client, "/api/play/step", {"frames": 25})
    post(client, "/api/play/buttons", {"buttons": ["RIGHT", "B"]})
    post(client, "/api/play/step", {"frames": 5})
    end = ram(studio_session)
    written = post(client, "/api/movies/stop", {"name": "run"})
    path = studio_game / "movies" / "run.bk2"
    assert Path(written["path"]) == path and written["frames"] == 30
    movie = read_bk2(path)
    assert movie.game == "Dasher-Genesis" and movie.frames == [(RIGHT, 0)] * 25 + [(RIGHT | 1, 0)] * 5
    assert "run" in [m["name"] for m in client.get("/api/movies").json()["movies"]]
    post(client, "/api/movies/stop", {"name": "run"}, status=400)  # nothing is being recorded

    post(client, "/api/play/reset", {"state": "Zone3.Act1"})  # somewhere else, then replay
    post(client, "/api/play/speed", {"value": 4})
    assert post(client, "/api/movies/play", {"name": "run"})["frames"] == 30
    deadline = time.monotonic() + 120
    while client.get("/api/status").json()["replaying"] and time.monotonic() < deadline:
        time.sleep(0.05)
    post(client, "/api/play/speed", {"value": 1})
    assert client.get("/api/status").json()["paused"]  # a replay ends paused, at its last frame
    assert (ram(studio_session) == end).all()


def test_a_replay_started_after_the_last_page_left_plays_to_its_end_when_the_grace_period_runs_out(
    client, studio_session
):
    """The page closes, a script replays a movie, and the grace period runs out in the middle: the replay goes on.

    The grace timer stopped the thread whatever ran on it, leaving the status ``replaying`` and not paused for
    ever with no thread to play. In this file the last socket test's timer fired 0.08 to 0.2 s before the
    replay test's replay began: a little later, and that replay never ended (and the speed test, which the
    first socket test's timer lands in, played no frame at 1x). A frame hook ends the grace period at the
    replay's first frame, on purpose.
    """
    paused_at(client)
    post(client, "/api/movies/record")
    post(client, "/api/play/step", {"frames": 10})
    post(client, "/api/movies/stop", {"name": "graceful"})
    with socket(client):
        pass  # the last page leaves: paused, the grace period begins
    assert studio_session.paused

    def grace_over(s: Session) -> None:
        remove()
        s._leave()  # what the grace timer calls when it runs out

    remove = studio_session.on_frame(grace_over)
    start = studio_session.frame
    post(client, "/api/play/speed", {"value": 8})
    assert post(client, "/api/movies/play", {"name": "graceful"})["frames"] == 10
    deadline = time.monotonic() + 120  # generous: a loaded machine is slow, never wrong
    while studio_session.running and client.get("/api/status").json()["replaying"] and time.monotonic() < deadline:
        time.sleep(0.05)
    status = client.get("/api/status").json()
    post(client, "/api/play/speed", {"value": 1})
    assert not status["replaying"] and status["paused"] and status["frame"] == start + 10, status


def test_a_movie_is_not_overwritten_unless_asked(client, studio_session):
    paused_at(client)
    for force, status in ((False, 200), (False, 409), (True, 200)):
        post(client, "/api/movies/record")
        post(client, "/api/play/step", {"frames": 3})
        post(client, "/api/movies/stop", {"name": "twice", "force": force}, status=status)


def test_a_corrupt_movie_is_a_json_error_and_the_server_lives_on(client, studio_session, studio_game):
    (studio_game / "movies" / "junk.bk2").write_bytes(b"PK\x03\x04 not really a zip" * 10)
    answer = post(client, "/api/movies/play", {"name": "junk"}, status=400)
    assert answer["kind"] == "MovieError"
    unknown = post(client, "/api/movies/play", {"name": "Zone1.Act"}, status=404)
    assert "Did you mean" in unknown["error"]
    assert client.get("/api/status").status_code == 200
    assert post(client, "/api/play/step", {"frames": 1})["paused"]


def test_a_shipped_solution_movie_replays(client, studio_session):
    answer = post(client, "/api/movies/play", {"name": "Zone1.Act1.bk2"})
    assert answer["frames"] > 0
    post(client, "/api/play/pause")


def test_screen_png(client):
    answer = client.get("/api/screen.png")
    assert answer.status_code == 200 and answer.content[:8] == b"\x89PNG\r\n\x1a\n"
    assert struct.unpack(">II", answer.content[16:24]) == (320, 224)


# --- validate, new game ----------------------------------------------------------------------------------


def test_validate_reports_as_json_while_the_game_plays_on(client, studio_session):
    post(client, "/api/play/speed", {"value": 1})
    post(client, "/api/play/resume")
    stages: list[str] = []

    def drain(ws) -> None:  # screens keep coming while the check runs: read them as a page would
        while "done" not in stages:
            message = ws.receive()
            if message.get("text") and json.loads(message["text"])["type"] == "validate":
                stages.append(json.loads(message["text"])["stage"])

    with socket(client) as ws:
        reader = threading.Thread(target=drain, args=(ws,), daemon=True)
        reader.start()
        start = studio_session.frame
        report = post(client, "/api/validate", {"frames": 10})
        played = studio_session.frame - start
        reader.join(timeout=120)
    post(client, "/api/play/pause")
    assert report["game"] == "Dasher-Genesis" and report["counts"]["pass"] > 10
    failed = [r for r in report["results"] if r["status"] == "fail"]
    # Only what the tests above broke on purpose (a corrupt state, a junk movie) may fail.
    assert all("Broken" in r["state"] + r["message"] or "junk" in r["message"] for r in failed), failed
    assert {"schema", "state loads"} <= {r["check"] for r in report["results"]}
    assert played > 0  # the session kept playing while the check ran
    assert "done" in stages
    bad = post(client, "/api/validate", {"frames": -1}, status=400)
    assert "frames" in bad["error"]


def test_new_game_from_a_rom_file_then_the_session_plays_it(tmp_path, monkeypatch):
    from runner_rom import write_runner_rom

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))  # new games go to the user's data folder
    monkeypatch.delenv("RETROKIT_GAMES", raising=False)
    rom = write_runner_rom(tmp_path / "runner.bin")
    session = Session("Dasher-Genesis", "Zone1.Act1")
    with TestClient(create_app(session, token=TOKEN, port=PORT), base_url=BASE,
                    headers={"X-Retrokit-Token": TOKEN}) as client:
        fifo = tmp_path / "fifo.md"
        os.mkfifo(fifo)
        refused = post(client, "/api/newgame", {"rom": str(fifo), "name": "Fifo-Genesis"}, status=400)
        assert refused["kind"] == "FileSystemError" and "FIFO" in refused["error"]
        made = post(client, "/api/newgame", {"rom": str(rom), "name": "Runner-Genesis"})
        assert made["game"] == "Runner-Genesis" and Path(made["folder"]) == tmp_path / "data" / "games" / "Runner-Genesis"
        assert made["info"]["game"] == "Runner-Genesis" and made["info"]["states"] == []
        status = post(client, "/api/play/step", {"frames": 3})
        assert status["game"] == "Runner-Genesis"
        post(client, "/api/play/reset", {})  # no states: power-on, and a movie recorded from there starts there
        post(client, "/api/movies/record")
        post(client, "/api/play/step", {"frames": 4})
        assert read_bk2(post(client, "/api/movies/stop", {"name": "boot"})["path"]).frames == [(0,)] * 4  # one player
        again = post(client, "/api/newgame", {"rom": str(rom), "name": "Runner-Genesis"}, status=409)
        assert again["kind"] == "FileConflictError"
        back = client.post("/api/game", json={"game": "Dasher-Genesis", "state": "Zone2.Act1"}).json()
        assert back["game"] == "Dasher-Genesis" and back["status"]["state"] == "Zone2.Act1"
        outside = post(client, "/api/game", {"game": str(DASHER)}, status=403)
        assert outside["kind"] == "AccessDeniedError"
        typo = post(client, "/api/game", {"game": "Dasher-Genesys"}, status=404)
        assert "Did you mean" in typo["error"]


def test_a_studio_nobody_opened_does_not_run_the_emulator():
    idle = Session("Dasher-Genesis", "Zone1.Act1")
    try:
        with TestClient(create_app(idle, token=TOKEN, port=PORT), base_url=BASE):
            time.sleep(0.5)
            assert not idle.running and idle.frame == 0
    finally:
        idle.close()


def test_a_reset_while_paused_shows_the_state_it_loaded(client, studio_session):
    screens = []
    for state in ("Zone1.Act1", "Zone3.Act1", "Zone1.Act1"):
        paused_at(client, state)
        screens.append(client.get("/api/screen.png").content)
    assert screens[0] != screens[1] and screens[0] == screens[2]
