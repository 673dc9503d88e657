"""The studio in headless Chromium against another local page, and a fresh studio's canvas (issue 31, items 1 and 7).

Another page served from 127.0.0.1 on another port is the same *site* as the
studio, so the browser sends it the studio's token cookie: a form posted as
``text/plain`` or a no-cors ``fetch`` from it reached the studio's routes.
Here a second local server serves such pages to the same browser that opened
the studio, and the studio must refuse them, change nothing, and keep every
response out of frames.

One studio serves the module's tests, each leaving it as it found it (the speed at 1x); the test of a
fresh studio's canvas starts its own.
"""

from __future__ import annotations

import hashlib
import http.server
import shutil
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from chromium import until  # first: it skips this module where Chromium is missing
from selenium import webdriver
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from studioproc import StudioProcess

from retrokit.studio.push import WINDOW

REPO = Path(__file__).resolve().parent.parent
DASHER = REPO / "games" / "Dasher-Genesis"
pytestmark = pytest.mark.timeout(900)


def start_studio(root: Path) -> StudioProcess:
    shutil.copytree(DASHER, root / "Dasher-Genesis")
    return StudioProcess(root / "Dasher-Genesis", root / "data", root)


def stop_studio(server: StudioProcess) -> None:
    err = server.stop()
    assert "Traceback" not in err, err


@pytest.fixture(scope="module")
def studio_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Where the module's studio runs and writes (its game's copy, its data folder)."""
    return tmp_path_factory.mktemp("studio")


@pytest.fixture(scope="module")
def studio(studio_root: Path) -> Iterator[StudioProcess]:
    server = start_studio(studio_root)
    yield server
    stop_studio(server)


@pytest.fixture
def fresh_studio(tmp_path: Path) -> Iterator[StudioProcess]:
    """A studio of this test's own, that no page has opened yet."""
    server = start_studio(tmp_path)
    yield server
    stop_studio(server)


def open_studio(driver: webdriver.Chrome, studio: StudioProcess) -> None:
    driver.get(studio.url)
    until("the page to start", lambda: driver.execute_script("return document.body.dataset.ready"))
    until("the socket", lambda: driver.find_element(By.ID, "connection").text == "connected")


# --- another local page ----------------------------------------------------------------------------------

ATTACKS = {
    # A form posts text/plain whose body reads as JSON: {"value": 4, "x": "="}
    "form.html": """<form id=f method=POST enctype=text/plain action="{studio}/api/play/speed">
<input name='{{"value": 4, "x": "' value='"}}'></form><script>document.getElementById("f").submit()</script>""",
    # A no-cors fetch, with the cookie: text/plain, and a Blob with no type at all.
    "fetch.html": """<script>
const post = (route, body) => fetch("{studio}/api/" + route, {{method: "POST", mode: "no-cors",
  credentials: "include", body}});
Promise.allSettled([
  post("states/save", JSON.stringify({{name: "Planted"}})),
  post("states/save", new Blob([JSON.stringify({{name: "Planted2"}})])),
  post("play/speed", JSON.stringify({{value: 8}})),
]).then(() => {{ document.title = "sent"; }});
</script>""",
    "frame.html": """<iframe id=f src="{studio_url}" width=600 height=400></iframe>""",
}


@pytest.fixture
def other_page(tmp_path: Path, studio: StudioProcess) -> Iterator[str]:
    """A second local server, on another port of 127.0.0.1, serving pages that try to drive the studio."""
    folder = tmp_path / "other"
    folder.mkdir()
    for name, page in ATTACKS.items():
        (folder / name).write_text(page.format(studio=studio.origin, studio_url=studio.url))

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, directory=str(folder), **kwargs)

        def log_message(self, *args) -> None:
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Quiet)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()


def test_another_local_page_cannot_drive_the_studio(browser, studio, other_page, studio_root):
    open_studio(browser, studio)  # the browser now holds the token cookie, as the user's does
    assert studio.request("GET", "/api/status")[1]["speed"] == 1
    browser.get(f"{other_page}/form.html")
    until("the form's answer", lambda: "/api/play/speed" in browser.current_url and browser.page_source)
    assert "AccessDeniedError" in browser.page_source
    browser.get(f"{other_page}/fetch.html")
    until("the fetches to settle", lambda: browser.title == "sent")
    assert studio.request("GET", "/api/status")[1]["speed"] == 1  # no speed changed
    made = [p.name for p in studio_root.rglob("Planted*")]
    assert not made, made  # no state saved
    # In a frame of another page, the studio's page is not shown at all.
    browser.get(f"{other_page}/frame.html")
    browser.switch_to.frame(until("the frame", lambda: browser.find_element(By.ID, "f")))
    until("the frame to settle", lambda: browser.execute_script("return document.readyState") == "complete")
    assert not browser.find_elements(By.ID, "screen")
    browser.switch_to.default_content()
    # The studio's own page still works under its content security policy.
    open_studio(browser, studio)
    browser.find_element(By.ID, "speed").send_keys("2")
    until("the speed to change from the page", lambda: studio.request("GET", "/api/status")[1]["speed"] == 2)
    assert studio.request("POST", "/api/play/speed", {"value": 1})[0] == 200  # as the other tests found it


def test_every_response_carries_the_security_headers(studio):
    for method, route, body in (("GET", "/", None), ("GET", "/api/status", None), ("POST", "/api/play/pause", {}),
                                ("GET", "/api/nowhere", None)):  # fmt: skip
        _, _, headers = studio.request(method, route, body)
        assert "frame-ancestors 'none'" in headers["content-security-policy"], (route, headers)
        assert headers["x-content-type-options"] == "nosniff"
        assert headers["referrer-policy"] == "no-referrer"
        assert headers["cache-control"] == "no-store"


@pytest.mark.parametrize(
    "headers, status",
    [
        ({"Origin": "http://127.0.0.1:9"}, 403),
        ({"Sec-Fetch-Site": "same-site"}, 403),
        ({"Sec-Fetch-Site": "cross-site"}, 403),
        ({"Origin": "null"}, 403),
        ({"Sec-Fetch-Site": "same-origin"}, 200),
    ],
    ids=["other-origin", "same-site", "cross-site", "null-origin", "same-origin"],
)
def test_a_state_change_must_come_from_the_studios_own_origin(studio, headers, status):
    assert studio.request("POST", "/api/play/pause", {}, headers)[0] == status


def test_a_state_change_without_the_token_header_must_be_json(studio):
    cookie = {"X-Retrokit-Token": None, "Cookie": f"retrokit-studio-{studio.origin.rsplit(':', 1)[1]}={studio.token}"}
    assert studio.request("POST", "/api/play/pause", {}, {**cookie, "Content-Type": "text/plain"})[0] == 403
    assert studio.request("POST", "/api/play/pause", {}, {**cookie, "Content-Type": "application/json"})[0] == 200


# --- a fresh studio's canvas -------------------------------------------------------------------------------


# Counts the messages the page's sockets receive (window.socketMessages), around the page's own handlers.
COUNT_MESSAGES = """
window.socketMessages = 0;
window.WebSocket = class extends window.WebSocket {
  constructor(...args) {
    super(...args);
    this.addEventListener("message", () => { window.socketMessages += 1; });
  }
};
"""


def canvas_hash(driver: webdriver.Chrome) -> str:
    return hashlib.sha1(driver.execute_script("return document.getElementById('screen').toDataURL()").encode()).hexdigest()


def test_a_fresh_studio_draws_what_is_played(browser, fresh_studio):
    """Open a fresh studio and play at once, without Reset or Resume: the canvas shows the game moving."""
    studio = fresh_studio
    counter = browser.execute_cdp_cmd("Page.addScriptToEvaluateOnNewDocument", {"source": COUNT_MESSAGES})
    try:
        open_studio(browser, studio)
    finally:  # for this page only: the session's browser serves other tests next
        browser.execute_cdp_cmd("Page.removeScriptToEvaluateOnNewDocument", counter)
    until("a first picture", lambda: int(browser.find_element(By.ID, "screen").get_attribute("data-frame") or 0) > 0)
    first = canvas_hash(browser)
    start = studio.request("GET", "/api/screen.png")[1]
    browser.find_element(By.ID, "screen").click()
    ActionChains(browser).key_down(Keys.ARROW_RIGHT).perform()
    try:
        until("the RIGHT button to light up",
              lambda: "held" in browser.find_element(By.CSS_SELECTOR, '[data-button="RIGHT"]').get_attribute("class"))
        until("the server's frames to run on", lambda: studio.request("GET", "/api/status")[1]["frame"] > 300)
        until("the canvas to show another picture", lambda: canvas_hash(browser) != first)
    finally:
        ActionChains(browser).key_up(Keys.ARROW_RIGHT).perform()
    assert studio.request("GET", "/api/screen.png")[1] != start

    # However long it played, the page is at most a few messages behind the server: the server sends a page
    # that says what it handled at most a window ahead (retrokit/studio/push.py). Counted in messages, not in
    # frames or seconds, as a loaded machine's browser draws fewer frames: paused now, the canvas reaches the
    # frame the game stopped on within a window and the newest of each message, where a backlog held hundreds.
    assert studio.request("POST", "/api/play/pause", {})[0] == 200
    stopped = studio.request("GET", "/api/status")[1]
    assert stopped["paused"]
    handled = browser.execute_script("return window.socketMessages")
    until("the canvas to show the frame the game paused on",
          lambda: int(browser.find_element(By.ID, "screen").get_attribute("data-frame")) == stopped["frame"])
    more = browser.execute_script("return window.socketMessages") - handled
    assert more <= WINDOW + 4, more  # the window, the last screen, a status and the newest of others
