"""The studio's page in headless Chromium, driven as a user would: the server, the page and what tests read off it.

A real ``retrokit studio`` server runs in a child process on a free port
(:class:`Studio`), on a copy of a game's folder and an empty data folder;
the session's one headless Chromium (tests/conftest.py's ``browser``) opens
the URL it prints, and :class:`Page` drives it as a user would.

With ``RETROKIT_SCREENSHOTS=1`` the tests also write the screenshots of
docs/studio.md (``docs/images/studio-*.png``); normal runs leave the docs alone.

Importing this module skips the importing test module where Chromium is missing.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from chromium import WAIT, until  # first: it skips the importing module where Chromium is missing
from selenium import webdriver
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import Select
from studioproc import StudioProcess

REPO = Path(__file__).resolve().parent.parent
DASHER = REPO / "games" / "Dasher-Genesis"
IMAGES = REPO / "docs" / "images"

# --- the server and the browser ---------------------------------------------------------------------------


class Studio:
    """A ``retrokit studio`` child process on a copy of a game's folder (Dasher's), and where its files go.

    Args:
        root: The folder it runs in: the copies go to ``root/games``, its data folder is ``root/data``.
        source: The game it plays first.
        others: More game folders copied beside it, which it opens by name (:meth:`open_game`).
    """

    def __init__(self, root: Path, source: Path = DASHER, others: tuple[Path, ...] = ()) -> None:
        games = root / "games"
        for folder in (source, *others):
            shutil.copytree(folder, games / folder.name)
        self.game = games / source.name
        self.data = root / "data"
        self.data.mkdir()
        self.server = StudioProcess(self.game, self.data, root, env={"RETROKIT_GAMES": str(games)})
        self.process, self.url = self.server.process, self.server.url

    def open_game(self, name: str) -> None:
        """Play another of its games, as the page's Open does (``POST /api/game``)."""
        status, answer, _ = self.server.request("POST", "/api/game", {"game": name})
        assert status == 200 and answer["game"] == name, answer
        self.game = self.game.parent / name

    def stop(self) -> str:
        """Ctrl-C, as a user stops it; return what it printed on stderr."""
        return self.server.stop()


@contextlib.contextmanager
def running_studio(root: Path, source: Path = DASHER, others: tuple[Path, ...] = ()) -> Iterator[Studio]:
    """A :class:`Studio` in ``root`` for a block (a test module's); it must stop cleanly on Ctrl-C at the end."""
    server = Studio(root, source, others)
    try:
        yield server
    finally:
        err = server.stop()
    assert server.process.returncode == 0, err
    assert "Traceback" not in err


class Page:
    """The studio's page, as a user sees and drives it."""

    def __init__(self, driver: webdriver.Chrome, studio: Studio) -> None:
        self.driver = driver
        self.studio = studio

    def open(self, tab: str = "search") -> Page:
        """Load the page afresh (a URL differing only in its #tab would not reload it), on a tab."""
        self.driver.get("about:blank")
        self.driver.get(f"{self.studio.url}#{tab}")
        until("the page to start", lambda: self.driver.execute_script("return document.body.dataset.ready"))
        until("the socket", lambda: self.text("connection") == "connected")
        until("a screen", lambda: self.frame() > 0)
        return self

    def el(self, element_id: str):
        return self.driver.find_element(By.ID, element_id)

    def text(self, element_id: str) -> str:
        """An element's text as shown (one round trip: see :meth:`frame`)."""
        shown = self.driver.execute_script("const e = document.getElementById(arguments[0]); return e && e.innerText;", element_id)
        if shown is None:
            raise AssertionError(f"no element #{element_id} on the page")
        return shown

    def click(self, element_id: str) -> None:
        self.el(element_id).click()

    def type(self, element_id: str, text: str) -> None:
        box = self.el(element_id)
        box.clear()
        box.send_keys(text)

    def tab(self, name: str) -> None:
        button = self.driver.find_element(By.CSS_SELECTOR, f'#tabs button[data-panel="{name}"]')
        # Scrolled to the middle as a user would: scrolled down a long panel, the tab is under the sticky header.
        self.driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", button)
        button.click()
        until(f"the {name} panel", lambda: self.el(name).is_displayed())

    # What the tests read often is read in one script: each WebDriver call is a round trip to a browser
    # busy drawing the game, which took a second or more on a loaded machine.

    def frame(self) -> int:
        """The frame number of the screen drawn on the canvas."""
        return int(self.driver.execute_script("return document.getElementById('screen').dataset.frame") or 0)

    def legend(self) -> dict[str, str]:
        """The page's buttons, each with the key shown on it."""
        return self.driver.execute_script(
            "return Object.fromEntries(Array.from(document.querySelectorAll('#buttons .pad-button'),"
            " (b) => [b.dataset.button, b.querySelector('kbd').innerText]));"
        )

    def message(self) -> str:
        return self.text("message")

    def said(self, start: str) -> str:
        """Wait for the message line to start with ``start`` (an error there fails at once)."""

        def check() -> str | None:
            shown, error = self.driver.execute_script(
                "const line = document.getElementById('message'); return [line.innerText, line.classList.contains('error')];"
            )
            if error:
                raise AssertionError(f"the page said: {shown}")
            return shown if shown.startswith(start) else None

        deadline = time.monotonic() + WAIT
        while time.monotonic() < deadline:
            try:
                found = check()
            except AssertionError:
                raise
            except Exception:  # noqa: BLE001
                found = None
            if found:
                return found
            time.sleep(0.1)
        raise AssertionError(f"waited for a message starting {start!r}; the page shows {self.message()!r}")

    def paused(self) -> bool:
        return self.text("run-state") == "paused"

    def pause(self) -> None:
        """Pause, and wait for the canvas to show the frame the game paused on.

        The status saying "paused" comes before the last screens (the server sends messages first), and a
        loaded browser draws them later still: a frame number read at once could be some frames old.
        """
        if not self.paused():
            self.click("pause")
        until("the game to pause", self.paused)
        until("the screen of the frame it paused on", lambda: self.frame() == self.studio.server.request(
            "GET", "/api/status")[1]["frame"])  # fmt: skip

    def resume(self) -> None:
        if self.paused():
            self.click("pause")
        until("the game to run", lambda: not self.paused())

    def reset(self, state: str) -> None:
        Select(self.el("reset-state")).select_by_value(state)
        self.click("reset")
        until(f"state {state}", lambda: self.text("current-state") == state)

    def advance(self, frames: int, *keys: str) -> None:
        """Hold ``keys`` on the keyboard while the game advances ``frames`` frames (paused: frame advance)."""
        self.type("step-frames", str(frames))
        start = self.frame()
        actions = ActionChains(self.driver)
        for key in keys:
            actions.key_down(key, self.el("screen"))
        actions.perform()
        self.click("step")
        until(f"{frames} frames", lambda: self.frame() >= start + frames)
        actions = ActionChains(self.driver)
        for key in keys:
            actions.key_up(key)
        actions.perform()

    def settled(self) -> None:
        """Wait for the Watch panel's values to be those of the frame on the screen (paused: exact)."""
        until("the fields of this frame", lambda: self.el("watch-table").get_attribute("data-frame") == str(self.frame()))

    def field(self, name: str) -> str:
        """A field's live value in the Watch panel."""
        value = self.driver.execute_script(  # textContent: also while the Watch tab is hidden
            "const cell = document.querySelector(`#watch-rows tr[data-field=\"${arguments[0]}\"] td.live`);"
            " return cell && cell.textContent;",
            name,
        )
        if value is None:
            raise AssertionError(f"no field {name} in the Watch panel")
        return value

    def shot(self, name: str) -> None:
        """Write docs/images/studio-NAME.png, only when asked (RETROKIT_SCREENSHOTS=1)."""
        if os.environ.get("RETROKIT_SCREENSHOTS"):
            time.sleep(0.5)  # the newest screen and live values drawn
            self.driver.save_screenshot(str(IMAGES / f"studio-{name}.png"))

    def errors(self) -> list[str]:
        """The browser console's errors (a script that failed)."""
        return [e["message"] for e in self.driver.get_log("browser") if e["level"] == "SEVERE"]


def canvas_pixels(page: Page) -> str:
    return page.driver.execute_script("return document.getElementById('screen').toDataURL()")


def canvas_colours(page: Page) -> int:
    """How many distinct colours the screen's canvas shows (1: a blank screen)."""
    return page.driver.execute_script(
        "const c = document.getElementById('screen');"
        "const d = new Uint32Array(c.getContext('2d').getImageData(0, 0, c.width, c.height).data.buffer);"
        "return new Set(d).size;"
    )


def type_scenario(page: Page, text: str) -> None:
    """Replace the editor's text by typing, as a user would (CodeMirror keeps the indentation of a new line)."""
    page.driver.find_element(By.CSS_SELECTOR, "#scenario .CodeMirror").click()
    chord = Keys.COMMAND if sys.platform == "darwin" else Keys.CONTROL
    ActionChains(page.driver).key_down(chord).send_keys("a").key_up(chord).send_keys(Keys.DELETE).perform()
    ActionChains(page.driver).send_keys(text).perform()


def editor_text(page: Page) -> str:
    return page.driver.execute_script("return document.querySelector('#scenario .CodeMirror').CodeMirror.getValue()")


def click_pixel(page: Page, x: int, y: int) -> None:
    """Click the console pixel (x, y) of the screen, wherever and however large the canvas is drawn."""
    canvas = page.el("screen")
    size = canvas.size
    scale = size["width"] / int(canvas.get_attribute("width"))
    dx = round((x + 0.5) * scale - size["width"] / 2)  # Selenium's offsets are from the element's centre
    dy = round((y + 0.5) * scale - size["height"] / 2)
    ActionChains(page.driver).move_to_element_with_offset(canvas, dx, dy).click().perform()


def dasher_studio(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Studio]:
    """A studio on a copy of Dasher for a test module (the ``studio`` fixture of :func:`fixtures`)."""
    with running_studio(tmp_path_factory.mktemp("studio")) as server:
        yield server


def module_page(chromium_session: webdriver.Chrome, studio: Studio, tab: str = "search") -> Iterator[Page]:
    """The studio's page loaded once for a test module, on ``tab``; its tests go to their panels by their tabs.

    A load costs Chromium about a CPU-second (the page builds every panel) and the server a third of one: a fresh
    load for each test cost a module more than its steps did. The tests that are about a load (a reload restores an
    unsaved edit) call :meth:`Page.open` themselves.
    """
    from chromium import fresh

    page = Page(fresh(chromium_session), studio).open(tab)
    yield page
    page.driver.get("about:blank")  # off the page: the server pauses, and the next module finds a blank browser


def fixtures() -> tuple:
    """The fixtures ``studio`` (a module's, on Dasher) and ``page`` (:func:`module_page`), to assign to names."""
    return (pytest.fixture(dasher_studio, scope="module", name="studio"),
            pytest.fixture(module_page, scope="module", name="page"))  # fmt: skip
