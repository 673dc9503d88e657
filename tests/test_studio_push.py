"""A page slower than the game never falls behind the server: what it has not handled, the server holds back.

A real studio runs in a child process; the page is a WebSocket client that
takes a tenth of a second per message (as a page drawing a long candidates
list does) and acknowledges each, as the studio's page does. Without the
window the operating system's buffers held seconds of screens between them.
"""

from __future__ import annotations

import json
import shutil
import time
from pathlib import Path

import pytest
from studioproc import StudioProcess

websockets = pytest.importorskip("websockets.sync.client", reason="websockets is not installed")

REPO = Path(__file__).resolve().parent.parent
DASHER = REPO / "games" / "Dasher-Genesis"
SLOW = 0.1  # seconds a message takes the slow page: six game frames

pytestmark = pytest.mark.timeout(300)


@pytest.fixture(scope="module")
def studio(tmp_path_factory: pytest.TempPathFactory):
    """One studio for the module: each test asks for the play it needs (a new one took seconds to start)."""
    root = tmp_path_factory.mktemp("studio")
    shutil.copytree(DASHER, root / "Dasher-Genesis")
    server = StudioProcess(root / "Dasher-Genesis", root / "data", root)
    yield server
    err = server.stop()
    assert "Traceback" not in err, err


def frame_of(message: bytes) -> int:
    return int.from_bytes(message[8:12], "little")


def test_a_slow_page_gets_the_newest_screens_and_its_pause_at_once(studio):
    url = studio.origin.replace("http://", "ws://") + f"/ws?token={studio.token}&ack=1"
    with websockets.connect(url, max_size=None) as ws:
        ws.send(json.dumps({"type": "resume"}))  # playing, whatever another test left
        received, lags = 0, []
        while len(lags) < 20:  # 2 s of a slow page: without the window its lag grew 6 frames a message
            message = ws.recv(timeout=60)
            received += 1
            time.sleep(SLOW)  # the page is busy with it
            if isinstance(message, bytes):
                lags.append(studio.request("GET", "/api/status")[1]["frame"] - frame_of(message))
            ws.send(json.dumps({"type": "ack", "received": received}))
        ws.send(json.dumps({"type": "pause"}))
        ws.send(json.dumps({"type": "ack", "received": received}))
        before_pause = 0
        while True:
            message = ws.recv(timeout=60)
            received += 1
            ws.send(json.dumps({"type": "ack", "received": received}))
            if isinstance(message, str) and json.loads(message).get("paused") is True:
                break
            before_pause += 1
    # Each screen is at most a window of messages old (a few tenths of a second: under 60 frames) when it
    # arrives, however long the page played; without the window, the lag grew by seconds.
    assert max(lags[10:]) < 60, lags
    assert before_pause <= 6, before_pause  # the pause's status comes after what was sent already, no more


def test_a_wrong_ack_is_a_clear_error_on_the_socket(studio):
    url = studio.origin.replace("http://", "ws://") + f"/ws?token={studio.token}"
    with websockets.connect(url, max_size=None) as ws:
        ws.send(json.dumps({"type": "ack", "received": 10**9}))
        while True:
            message = ws.recv(timeout=60)
            if isinstance(message, str) and json.loads(message)["type"] == "error":
                assert "Expected 'received' to be how many messages the page handled" in json.loads(message)["error"]
                break
