"""The studio's guards and faults: token, Origin, Host, paths however encoded, hostile bodies, a busy port, Ctrl-C.

HTTP and WebSocket checks run on a real Dasher session through Starlette's
TestClient; the port and Ctrl-C checks run a real ``retrokit studio``
subprocess.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import urllib.request
from pathlib import Path

import pytest
from starlette.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from retrokit.errors import AccessDeniedError
from retrokit.studio.app import create_app
from retrokit.studio.security import MAX_BODY, resolve_path
from retrokit.studio.server import bind
from retrokit.studio.session import Session

REPO = Path(__file__).resolve().parent.parent
DASHER = REPO / "games" / "Dasher-Genesis"
TOKEN = "secret-token"
PORT = 8722
BASE = f"http://127.0.0.1:{PORT}"


@pytest.fixture(scope="module")
def app(studio_session: Session):
    return create_app(studio_session, token=TOKEN, port=PORT)


@pytest.fixture(scope="module")
def bare(app, client):
    """A client that sends no token unless told (``client`` runs the app's lifespan: the session's life)."""
    return TestClient(app, base_url=BASE)


@pytest.fixture(scope="module")
def client(app):
    with TestClient(app, base_url=BASE, headers={"X-Retrokit-Token": TOKEN}) as client:
        yield client


def refused(answer, status: int = 403, kind: str = "AccessDeniedError") -> str:
    assert answer.status_code == status, answer.text
    body = answer.json()
    assert body["kind"] == kind and "\n" not in body["error"]
    return body["error"]


# --- the token ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("route", ["/api/info", "/", "/index.html", "/api/states", "/api/nowhere"])
def test_a_request_without_the_token_is_refused(bare, route):
    assert "token" in refused(bare.get(route))
    assert "wrong token" in refused(bare.get(route, headers={"X-Retrokit-Token": "guess"}))
    assert "wrong token" in refused(bare.get(route + "?token=" + TOKEN[:-1]))


def test_a_post_without_the_token_changes_nothing(bare, studio_session):
    speed = studio_session.speed
    refused(bare.post("/api/play/speed", json={"value": 0.5}))
    assert studio_session.speed == speed


def test_the_token_in_the_query_sets_a_cookie_the_page_then_uses(app, client):
    browser = TestClient(app, base_url=BASE)
    page = browser.get(f"/?token={TOKEN}")
    assert page.status_code == 200 and "SameSite=Strict" in page.headers["set-cookie"]
    assert "HttpOnly" in page.headers["set-cookie"]
    assert browser.get("/api/info").status_code == 200  # the cookie alone, as the page's scripts
    refused(TestClient(app, base_url=BASE).get("/api/info"))


def test_the_websocket_needs_the_token(bare):
    for url in (f"ws://127.0.0.1:{PORT}/ws", f"ws://127.0.0.1:{PORT}/ws?token=nope"):
        with pytest.raises(WebSocketDisconnect) as caught, bare.websocket_connect(url):
            pass
        assert caught.value.code == 1008
    with bare.websocket_connect(f"ws://127.0.0.1:{PORT}/ws?token={TOKEN}") as ws:
        assert json.loads(ws.receive_text())["type"] == "status"


@pytest.mark.parametrize("origin", ["http://evil.example", f"http://127.0.0.1:{PORT + 1}", "null",
                                    f"https://127.0.0.1:{PORT}"])
def test_a_websocket_from_another_origin_is_refused(bare, origin):
    url = f"ws://127.0.0.1:{PORT}/ws?token={TOKEN}"
    with pytest.raises(WebSocketDisconnect) as caught, bare.websocket_connect(url, headers={"Origin": origin}):
        pass
    assert caught.value.code == 1008 and "Origin" in caught.value.reason


@pytest.mark.parametrize("origin", [f"http://127.0.0.1:{PORT}", f"http://localhost:{PORT}"])
def test_a_websocket_from_the_studios_page_is_accepted(bare, origin):
    url = f"ws://127.0.0.1:{PORT}/ws?token={TOKEN}"
    with bare.websocket_connect(url, headers={"Origin": origin}) as ws:
        assert json.loads(ws.receive_text())["type"] == "status"


def test_another_host_is_refused_against_dns_rebinding(client):
    assert "Host" in refused(client.get("/api/info", headers={"Host": f"evil.example:{PORT}"}))
    assert client.get("/api/info", headers={"Host": f"localhost:{PORT}"}).status_code == 200


def test_the_server_binds_127_0_0_1_only():
    sock = bind(0)
    try:
        assert sock.getsockname()[0] == "127.0.0.1"
    finally:
        sock.close()


# --- paths ---------------------------------------------------------------------------------------------------


HOSTILE_NAMES = [
    "../../../etc/passwd",
    "..",
    "movies/../../../../etc/passwd",
    "%2e%2e/%2e%2e/%2e%2e/etc/passwd",
    "%2E%2E%2F%2E%2E%2Fetc%2Fpasswd",
    "%252e%252e%252f%252e%252e%252fetc%252fpasswd",
    "%25252e%25252e/x",
    "..%2f..%2f..%2fetc%2fpasswd",
    "..\\..\\etc\\passwd",
    "/etc/passwd",
    "%2fetc%2fpasswd",
    "~/x",
    "C:\\Windows\\win.ini",
    "run\x00.bk2",
    "run%00.bk2",
]


@pytest.mark.parametrize("name", HOSTILE_NAMES, ids=repr)
def test_the_resolver_refuses_a_way_out_however_encoded(tmp_path, name):
    base = tmp_path / "game" / "movies"
    base.mkdir(parents=True)
    with pytest.raises(AccessDeniedError, match="Expected a"):
        resolve_path(name, base, [tmp_path / "game"])


def test_the_resolver_refuses_a_symlink_out_of_the_folder(tmp_path):
    base = tmp_path / "game" / "movies"
    base.mkdir(parents=True)
    (tmp_path / "secret.bk2").write_bytes(b"x")
    (base / "link.bk2").symlink_to(tmp_path / "secret.bk2")
    (base / "inside.bk2").write_bytes(b"x")
    with pytest.raises(AccessDeniedError, match="symlink"):
        resolve_path("link.bk2", base, [tmp_path / "game"])
    assert resolve_path("inside.bk2", base, [tmp_path / "game"]) == base / "inside.bk2"
    assert resolve_path("sub/new.bk2", base, [tmp_path / "game"]) == base / "sub" / "new.bk2"


@pytest.mark.parametrize("name", HOSTILE_NAMES, ids=repr)
def test_a_request_naming_a_movie_outside_the_game_is_refused(client, name):
    answer = client.post("/api/movies/play", json={"name": name})  # ".." + ".bk2" is the plain name "...bk2": 404
    assert answer.status_code in (400, 403, 404), answer.text
    assert answer.json()["kind"] in ("AccessDeniedError", "InvalidArgumentError", "UnknownNameError")
    writing = client.post("/api/movies/stop", json={"name": name})
    assert writing.status_code in (400, 403) and writing.json()["kind"] in ("AccessDeniedError", "InvalidArgumentError")


def test_a_movie_symlinked_out_of_the_game_is_refused(client, studio_game, tmp_path):
    outside = tmp_path / "outside.bk2"
    shutil.copy(studio_game / "movies" / "Zone1.Act1.bk2", outside)
    (studio_game / "movies" / "escape.bk2").symlink_to(outside)
    assert "symlink" in refused(client.post("/api/movies/play", json={"name": "escape"}))


@pytest.mark.parametrize("path", ["/../../../../etc/passwd", "/%2e%2e/%2e%2e/%2e%2e/etc/passwd",
                                  "/%252e%252e/%252e%252e/etc/passwd", "/..%2f..%2f..%2fetc%2fpasswd"])
def test_static_files_do_not_leave_their_folder(client, path):
    answer = client.get(path)
    assert answer.status_code in (400, 403, 404) and b"root:" not in answer.content


# --- hostile bodies --------------------------------------------------------------------------------------------


POST_ROUTES = ["/api/play/buttons", "/api/play/step", "/api/play/speed", "/api/play/reset", "/api/states/load",
               "/api/states/save", "/api/states/default", "/api/movies/stop", "/api/movies/play",
               "/api/newgame", "/api/game", "/api/validate"]
HOSTILE_BODIES = [
    b"{", b"null", b"[]", b'"text"', b"42", b"\xff\xfe\x00", b"[" * 100_000 + b"]" * 100_000,
    b'{"name": 5, "buttons": "RIGHT", "frames": "ten", "value": true, "state": [], "rom": {}, "game": 1}',
    b'{"name": null, "buttons": [1, 2], "frames": 1e309, "value": -1, "state": "", "rom": "", "frames2": 0}',
    b'{"buttons": ["RIGTH"], "frames": 0, "value": 1e9, "state": "Zone1.Act9", "name": "", "game": "Nope"}',
]


@pytest.mark.parametrize("route", POST_ROUTES)
def test_hostile_bodies_get_4xx_json_errors_never_a_500(client, route):
    for body in HOSTILE_BODIES:
        answer = client.post(route, content=body, headers={"Content-Type": "application/json"})
        assert 400 <= answer.status_code < 500, (route, body[:40], answer.status_code, answer.text[:200])
        error = answer.json()
        assert set(error) == {"error", "kind"} and error["error"] and "\n" not in error["error"]
    assert client.get("/api/status").status_code == 200


def test_a_body_over_the_cap_is_refused_with_or_without_a_length(client):
    huge = b'{"name": "' + b"x" * (MAX_BODY + 10) + b'"}'
    assert refused(client.post("/api/states/save", content=huge), 413, "RequestTooLargeError")

    def chunks():
        yield b'{"name": "'
        for _ in range(MAX_BODY // 65536 + 2):
            yield b"x" * 65536
        yield b'"}'

    assert refused(client.post("/api/states/save", content=chunks()), 413, "RequestTooLargeError")


def test_unknown_names_get_a_did_you_mean(client):
    assert "Did you mean 'resume'" in refused(client.post("/api/play/resum", json={}), 404, "UnknownNameError")
    assert "Did you mean 'RIGHT'" in refused(client.post("/api/play/buttons", json={"buttons": ["RIGTH"]}), 404,
                                            "UnknownNameError")
    answer = client.get("/api/nowhere")
    assert answer.status_code == 404 and answer.json()["kind"] == "HTTPException"
    assert client.get("/api/play/pause").status_code == 405


# --- the process -----------------------------------------------------------------------------------------------------


def studio(*args: str) -> subprocess.Popen:
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    return subprocess.Popen([sys.executable, "-m", "retrokit", "studio", "Dasher-Genesis", "--no-browser", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)


def test_a_second_studio_on_a_busy_port_fails_with_one_clear_line():
    holder = bind(0)
    port = holder.getsockname()[1]
    try:
        proc = studio("--port", str(port))
        out, err = proc.communicate(timeout=120)
    finally:
        holder.close()
    assert proc.returncode == 2 and out == ""
    assert err.count("\n") == 1 and f"Expected port {port} on 127.0.0.1 to be free" in err and "--port" in err


def test_ctrl_c_ends_the_studio_cleanly_with_a_page_connected():
    from websockets.sync.client import connect

    proc = studio("--port", "0")
    try:
        line = proc.stdout.readline()
        assert line.startswith("retrokit studio: http://127.0.0.1:") and "?token=" in line
        url = line.split(": ", 1)[1].strip()
        base, token = url.split("/?token=")
        request = urllib.request.Request(base + "/api/info", headers={"X-Retrokit-Token": token})
        with urllib.request.urlopen(request, timeout=30) as answer:
            assert json.load(answer)["game"] == "Dasher-Genesis"
        with pytest.raises(urllib.error.HTTPError) as caught:
            urllib.request.urlopen(base + "/api/info", timeout=30)
        assert caught.value.code == 403
        with connect(base.replace("http", "ws") + "/ws?token=" + token, open_timeout=30) as ws:
            assert isinstance(ws.recv(timeout=30), (bytes, str))
            proc.send_signal(signal.SIGINT)
            _out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, err
    assert "Traceback" not in err


def test_a_port_already_taken_by_anything_else_is_the_same_error(tmp_path):
    with socket.socket() as other:
        other.bind(("127.0.0.1", 0))
        other.listen(1)
        port = other.getsockname()[1]
        from retrokit.errors import PortInUseError

        with pytest.raises(PortInUseError, match=f"retrokit studio --port {port + 1}"):
            bind(port)


def test_an_unknown_game_is_one_line_before_anything_listens():
    proc = subprocess.run([sys.executable, "-m", "retrokit", "studio", "Dasher-Genesys", "--no-browser", "--port", "0"],
                          check=False, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.count("\n") == 1 and "Did you mean 'Dasher-Genesis'" in proc.stderr


def test_a_state_symlinked_out_of_the_game_is_refused(client, studio_session, studio_game, tmp_path):
    outside = tmp_path / "outside.state"
    shutil.copy(studio_game / "Zone1.Act2.state", outside)
    (studio_game / "Linked.state").symlink_to(outside)
    studio_session.call_blocking(lambda s: s.refresh_game())
    assert "symlink" in refused(client.post("/api/states/load", json={"name": "Linked"}))
    assert "symlink" in refused(client.post("/api/play/reset", json={"state": "Linked"}))


def test_hostile_socket_messages_are_errors_and_the_session_lives_on(client, studio_session):
    url = f"ws://127.0.0.1:{PORT}/ws?token={TOKEN}"
    with client.websocket_connect(url) as ws:
        for text in ("{", "[]", '{"type": 5}', '{"type": "step", "frames": 1e9}', '{"type": "jump"}',
                     '{"type": "buttons", "buttons": "RIGHT"}', "[" * 50_000 + "]" * 50_000):
            ws.send_text(text)
            while True:
                message = ws.receive()
                if message.get("text") and json.loads(message["text"])["type"] == "error":
                    error = json.loads(message["text"])
                    break
            assert error["kind"] in ("InvalidArgumentError", "UnknownNameError") and "\n" not in error["error"]
        ws.send_bytes(b"\x00" * 10)  # the page never sends binary: the socket is closed, nothing else
    assert client.get("/api/status").status_code == 200
    assert client.post("/api/play/step", json={"frames": 1}).json()["paused"]
