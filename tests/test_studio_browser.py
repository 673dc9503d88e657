"""The studio's page in a real browser (issue 22's "Done when"), driven as a user would, on Dasher.

A real ``retrokit studio`` server runs in a child process on a free port, on a
copy of Dasher's game folder and an empty data folder in tmp_path; headless
Chromium (Debian's ``chromium`` and ``chromium-driver``, through Selenium)
opens the URL it prints. Each test is one step of the issue: open the studio,
play with the keyboard, find the lives with the search and add the field,
save a state, write a scenario and watch its reward live, validate. The
results are checked where they land: the screen, the RAM fields the page
shows, game.yaml, the .state file and its record.

With ``RETROKIT_SCREENSHOTS=1`` the tests also write the screenshots of
docs/studio.md (``docs/images/studio-*.png``); normal runs leave the docs alone.
"""

from __future__ import annotations

import os
import shutil
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml
from chromium import WAIT, chrome, until  # first: it skips this module where Chromium is missing
from selenium import webdriver
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import Select
from studioproc import StudioProcess

REPO = Path(__file__).resolve().parent.parent
DASHER = REPO / "games" / "Dasher-Genesis"
IMAGES = REPO / "docs" / "images"

pytestmark = pytest.mark.timeout(600)


# --- the server and the browser ---------------------------------------------------------------------------


class Studio:
    """A ``retrokit studio`` child process on a copy of a game's folder (Dasher's), and where its files go."""

    def __init__(self, root: Path, source: Path = DASHER) -> None:
        self.game = root / "games" / source.name
        shutil.copytree(source, self.game)
        self.data = root / "data"
        self.data.mkdir()
        self.server = StudioProcess(self.game, self.data, root)
        self.process, self.url = self.server.process, self.server.url

    def stop(self) -> str:
        """Ctrl-C, as a user stops it; return what it printed on stderr."""
        return self.server.stop()


@pytest.fixture(scope="module")
def studio(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Studio]:
    server = Studio(tmp_path_factory.mktemp("studio"))
    yield server
    err = server.stop()
    assert server.process.returncode == 0, err
    assert "Traceback" not in err


@pytest.fixture(scope="module")
def browser() -> Iterator[webdriver.Chrome]:
    with chrome() as driver:
        yield driver


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
        return self.el(element_id).text

    def click(self, element_id: str) -> None:
        self.el(element_id).click()

    def type(self, element_id: str, text: str) -> None:
        box = self.el(element_id)
        box.clear()
        box.send_keys(text)

    def tab(self, name: str) -> None:
        self.driver.find_element(By.CSS_SELECTOR, f'#tabs button[data-panel="{name}"]').click()
        until(f"the {name} panel", lambda: self.el(name).is_displayed())

    def frame(self) -> int:
        """The frame number of the screen drawn on the canvas."""
        return int(self.el("screen").get_attribute("data-frame") or 0)

    def message(self) -> str:
        return self.text("message")

    def said(self, start: str) -> str:
        """Wait for the message line to start with ``start`` (an error there fails at once)."""

        def check() -> str | None:
            line = self.el("message")
            if "error" in (line.get_attribute("class") or ""):
                raise AssertionError(f"the page said: {line.text}")
            return line.text if line.text.startswith(start) else None

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
        if not self.paused():
            self.click("pause")
        until("the game to pause", self.paused)

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
        cell = self.driver.find_element(By.CSS_SELECTOR, f'#watch-rows tr[data-field="{name}"] td.live')
        return cell.get_attribute("textContent")  # also while the Watch tab is hidden

    def shot(self, name: str) -> None:
        """Write docs/images/studio-NAME.png, only when asked (RETROKIT_SCREENSHOTS=1)."""
        if os.environ.get("RETROKIT_SCREENSHOTS"):
            time.sleep(0.5)  # the newest screen and live values drawn
            self.driver.save_screenshot(str(IMAGES / f"studio-{name}.png"))

    def errors(self) -> list[str]:
        """The browser console's errors (a script that failed)."""
        return [e["message"] for e in self.driver.get_log("browser") if e["level"] == "SEVERE"]


@pytest.fixture
def page(browser: webdriver.Chrome, studio: Studio) -> Page:
    return Page(browser, studio)


def canvas_pixels(page: Page) -> str:
    return page.driver.execute_script("return document.getElementById('screen').toDataURL()")


def canvas_colours(page: Page) -> int:
    """How many distinct colours the screen's canvas shows (1: a blank screen)."""
    return page.driver.execute_script(
        "const c = document.getElementById('screen');"
        "const d = new Uint32Array(c.getContext('2d').getImageData(0, 0, c.width, c.height).data.buffer);"
        "return new Set(d).size;"
    )


# --- the steps of the "Done when" -----------------------------------------------------------------


def test_open_the_studio_on_dasher(page):
    page.open()
    assert page.text("game-name") == "Dasher-Genesis (Genesis)"
    assert page.driver.title == "Dasher-Genesis · retrokit studio"
    screen = page.el("screen")
    assert (screen.get_attribute("width"), screen.get_attribute("height")) == ("320", "224")
    # The buttons are shown with their keys: the arrows are the D-pad, Enter is START.
    legend = {b.get_attribute("data-button"): b.find_element(By.TAG_NAME, "kbd").text
              for b in page.driver.find_elements(By.CSS_SELECTOR, "#buttons .pad-button")}  # fmt: skip
    assert {"UP": "↑", "DOWN": "↓", "LEFT": "←", "RIGHT": "→", "START": "Enter"}.items() <= legend.items()
    assert set(legend) == {"B", "A", "MODE", "START", "UP", "DOWN", "LEFT", "RIGHT", "C", "Y", "X", "Z"}
    # Every panel started (a failing one says so on the message line).
    assert "could not start" not in page.message()
    assert not page.errors()
    page.resume()
    page.shot("play")


def test_validate(page):
    """Before the other steps change the game: Dasher as shipped passes."""
    page.open("validate")
    page.click("validate-run")
    until("its progress", lambda: page.text("validate-summary").startswith("checking Dasher-Genesis: "))
    page.said("Validated Dasher-Genesis: ")
    summary = page.text("validate-summary")
    assert summary.startswith("Dasher-Genesis: passed (") and " 0 failed, " in summary  # the game as shipped
    rows = page.driver.find_elements(By.CSS_SELECTOR, "#validate-rows tr")
    assert len(rows) > 5
    statuses = {row.get_attribute("class") for row in rows}
    assert statuses <= {"pass", "warn", "fail", "skip"} and "pass" in statuses
    page.shot("validate")


def test_play_with_the_keyboard(page):
    page.open("watch")
    page.reset("Zone1.Act1")
    page.resume()
    until("the Watch panel's values", lambda: page.field("p1_x"))
    x0, frame0, pixels0 = int(page.field("p1_x")), page.frame(), canvas_pixels(page)
    ActionChains(page.driver).key_down(Keys.ARROW_RIGHT, page.el("screen")).perform()
    until("the RIGHT button to light up", lambda: "held" in page.driver.find_element(
        By.CSS_SELECTOR, '#buttons [data-button="RIGHT"]').get_attribute("class"))  # fmt: skip
    until("the player to run right", lambda: int(page.field("p1_x")) > x0 + 20)
    ActionChains(page.driver).key_up(Keys.ARROW_RIGHT).perform()
    assert page.frame() > frame0
    assert canvas_pixels(page) != pixels0  # the screen moved with the player
    # Paused, a reset shows the state chosen (loading a state does not draw it: the server does).
    page.pause()
    page.reset("Zone2.Act1")
    until("Zone 2 on the screen", lambda: canvas_colours(page) > 4)
    # Frame advance runs exactly the frames asked for, paused.
    before = page.frame()
    page.advance(30)
    assert page.frame() == before + 30 and page.paused()
    # The speed menu reaches the server: its status comes back with it.
    Select(page.el("speed")).select_by_value("2")
    until("2x", lambda: page.text("speed-shown") == "2×")
    Select(page.el("speed")).select_by_value("1")
    until("1x", lambda: page.text("speed-shown") == "1×")


def test_play_with_a_gamepad(page):
    """The Gamepad API's standard layout: button 15 is the D-pad's right. Headless Chromium has no pad, so the page
    is given one through the API it reads (navigator.getGamepads), as a browser would report a real pad."""
    page.open("watch")
    page.reset("Zone1.Act1")
    page.resume()
    until("the Watch panel's values", lambda: page.field("p1_x"))
    x0 = int(page.field("p1_x"))
    page.driver.execute_script(
        "const buttons = Array.from({length: 17}, (_, i) => ({pressed: i === 15, value: i === 15 ? 1 : 0}));"
        "window.fakePad = {index: 0, connected: true, mapping: 'standard', axes: [0, 0, 0, 0], buttons};"
        "navigator.getGamepads = () => [window.fakePad];"
        "window.dispatchEvent(new Event('gamepadconnected'));"
    )
    until("RIGHT held", lambda: "held" in page.driver.find_element(
        By.CSS_SELECTOR, '#buttons [data-button="RIGHT"]').get_attribute("class"))  # fmt: skip
    until("the player to run right", lambda: int(page.field("p1_x")) > x0 + 20)
    page.driver.execute_script("window.fakePad.buttons[15] = {pressed: false, value: 0};")
    until("RIGHT let go", lambda: "held" not in page.driver.find_element(
        By.CSS_SELECTOR, '#buttons [data-button="RIGHT"]').get_attribute("class"))  # fmt: skip
    page.pause()


def test_find_the_lives_with_the_search_and_add_the_field(page, studio):
    """docs/ramsearch.md's walkthrough, in the page: 3 lives, run into the pit twice, the byte is found."""
    page.open("search")
    page.pause()
    page.reset("Zone1.Act1")
    page.click("search-new")
    page.said("New search: 2,097,072 candidates.")

    def filter_(op: str, value: str = "") -> str:
        Select(page.el("search-op")).select_by_value(op)
        if value:
            page.type("search-value", value)
        page.click("search-apply")
        return page.said(f"{op}")

    assert filter_("equal", "3").startswith("equal 3: 2,097,072 -> ")
    page.advance(150, Keys.ARROW_RIGHT)  # into the first pit: a life lost
    assert "decreased --than previous" in filter_("decreased")
    page.advance(130)  # the respawn: the lives stay put
    filter_("unchanged")
    page.advance(200, Keys.ARROW_RIGHT)  # the pit again
    filter_("decreased")
    until("one group left", lambda: page.text("search-listed").startswith("1 groups"))
    rows = page.driver.find_elements(By.CSS_SELECTOR, "#search-rows tr")
    assert [(r.get_attribute("data-address"), r.get_attribute("data-type")) for r in rows] == [("0xFF002B", "|u1")]
    # Its value at each snapshot: the new search's, then one before each filter.
    assert rows[0].find_elements(By.TAG_NAME, "td")[4].text.split() == ["3", "3", "2", "2", "1"]
    page.shot("search")

    rows[0].click()  # the row fills the "add as field" form
    assert page.el("field-address").get_attribute("value") == "0xFF002B"
    assert page.el("field-type").get_attribute("value") == "|u1"
    page.type("field-name", "lives")
    page.type("field-lo", "0")
    page.type("field-hi", "9")
    page.click("field-add")
    page.said("Wrote field lives (0xFF002B, |u1, range [0, 9]) into ")
    fields = yaml.safe_load((studio.game / "game.yaml").read_text())["fields"]
    assert fields["lives"] == {"address": 0xFF002B, "type": "|u1", "range": [0, 9]}
    # The Watch panel lists it, with its live value.
    page.tab("watch")
    until("the new field in Watch", lambda: page.field("lives") == "1")

    # Undo and redo step through the filters; a poke shows in the live values.
    page.tab("search")
    page.click("search-undo")
    assert page.said("Undid decreased --than previous: ").endswith(" candidates.")
    assert page.text("search-count") != "12 candidates"
    page.click("search-redo")
    page.said("Redid decreased --than previous: 12 candidates.")
    page.type("poke-value", "9")
    page.click("poke")
    page.said("Poked 0xFF002B (|u1): it now reads 9.")
    until("9 lives in Watch", lambda: page.field("lives") == "9")


def test_save_a_state(page, studio):
    from retrokit.data.states import read_state_file

    page.open("search")
    page.pause()
    page.reset("Zone1.Act1")
    page.advance(40, Keys.ARROW_RIGHT)
    page.type("state-name", "Zone1.Run")
    page.el("state-default").click()
    page.click("state-save")
    line = page.said("State Zone1.Run saved")
    made = Path(line.rsplit(": ", 1)[1].rstrip("."))
    assert made.name == "Zone1.Run.state" and made.is_file()
    assert made.is_relative_to(studio.game.parent.parent)  # in the test's folders, nowhere else
    saved = read_state_file(made)
    assert saved.record is not None and saved.record.game == "Dasher-Genesis" and saved.record.describes(saved.data)
    until("the state listed as the default", lambda: page.driver.find_element(
        By.CSS_SELECTOR, '#states-rows tr[data-state="Zone1.Run"]').text.find("default") >= 0)  # fmt: skip
    game_yaml = next(p for p in (made.parent / "game.yaml", studio.game / "game.yaml") if p.is_file())
    assert yaml.safe_load(game_yaml.read_text())["states"]["default"] == "Zone1.Run"
    # The reset menu offers it, and loading it puts the game back there.
    assert "Zone1.Run" in [o.get_attribute("value") for o in Select(page.el("reset-state")).options]
    page.reset("Zone1.Run")
    page.shot("states")

    # The list's own buttons: another default, and a state loaded from there.
    row = page.driver.find_element(By.CSS_SELECTOR, '#states-rows tr[data-state="Zone1.Act2"]')
    row.find_element(By.CSS_SELECTOR, "button.make-default").click()
    page.said("Default state is now Zone1.Act2 (")
    assert yaml.safe_load(game_yaml.read_text())["states"]["default"] == "Zone1.Act2"
    page.driver.find_element(By.CSS_SELECTOR, '#states-rows tr[data-state="Zone1.Act2"] button.load').click()
    page.said("Loaded state Zone1.Act2.")
    until("Zone1.Act2 played", lambda: page.text("current-state") == "Zone1.Act2")


def type_scenario(page: Page, text: str) -> None:
    """Replace the editor's text by typing, as a user would (CodeMirror keeps the indentation of a new line)."""
    page.driver.find_element(By.CSS_SELECTOR, "#scenario .CodeMirror").click()
    chord = Keys.COMMAND if sys.platform == "darwin" else Keys.CONTROL
    ActionChains(page.driver).key_down(chord).send_keys("a").key_up(chord).send_keys(Keys.DELETE).perform()
    ActionChains(page.driver).send_keys(text).perform()


def editor_text(page: Page) -> str:
    return page.driver.execute_script("return document.querySelector('#scenario .CodeMirror').CodeMirror.getValue()")


def test_write_a_scenario_and_watch_its_reward_live(page, studio):
    page.open("scenario")
    page.pause()
    page.reset("Zone1.Act1")
    until("the scenario", lambda: "rewards:" in editor_text(page))
    # A typo: the error is listed and marked at the line and column the language reports.
    type_scenario(page, "description: run right\nreward: delta(p1_xx)\n")
    until("the compile error", lambda: page.text("scenario-state") == "does not compile")
    error = page.driver.find_element(By.CSS_SELECTOR, "#scenario-errors li")
    assert (error.get_attribute("data-line"), error.get_attribute("data-column")) == ("2", "15")
    assert "unknown field or definition 'p1_xx'. Did you mean 'p1_x'?" in error.text
    assert error.text.startswith("line 2, column 15: ")
    mark = page.driver.find_element(By.CSS_SELECTOR, "#scenario .cm-error-mark")
    assert mark.text == "p1_xx"
    assert not page.el("scenario-unsaved").get_attribute("hidden")
    page.shot("scenario-error")

    # A message quoting the user's text is shown as text, never parsed as HTML.
    type_scenario(page, "reward: delta(p1_x)\n<img src=x onerror=window.pwned=1>: 1\n")
    until("the unknown key", lambda: "unknown key '<img src=x onerror=window.pwned=1>'" in page.text("scenario-errors"))
    assert not page.driver.find_elements(By.CSS_SELECTOR, "#scenario-errors img")
    assert page.driver.execute_script("return window.pwned === undefined")

    # Fixed: it compiles; the server keeps the unsaved edit as a draft, and a reload restores it.
    type_scenario(page, "description: run right\nreward: delta(p1_x)\n")
    until("it to compile", lambda: page.text("scenario-state").startswith("compiles"))
    draft = studio.data / "studio" / "drafts" / "Dasher-Genesis" / "scenario.yaml"
    until("the draft on disk", lambda: draft.is_file() and "delta(p1_x)\n" in draft.read_text())
    page.open("scenario")  # the browser asks before leaving with an unsaved edit; WebDriver accepts
    until("the draft restored", lambda: editor_text(page) == "description: run right\nreward: delta(p1_x)\n")
    assert page.message().startswith("Restored your unsaved edit of scenario")

    page.click("scenario-live")
    page.said("Watching scenario's reward live")
    assert page.text("reward-total") == "0"
    page.advance(60, Keys.ARROW_RIGHT)
    until("the reward to grow", lambda: float(page.text("reward-total")) > 10)
    first = float(page.text("reward-total"))
    page.advance(30, Keys.ARROW_RIGHT)
    until("more reward", lambda: float(page.text("reward-total")) > first)
    assert page.text("reward-done") == "no"
    # The plot has been drawn: the canvas is not blank.
    blank = page.driver.execute_script(
        "const c = document.getElementById('reward-plot');"
        "const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
        "return d.every((v, i) => i % 4 === 3 || v === 0);"
    )
    assert blank is False
    page.shot("scenario")

    page.click("scenario-save")
    page.said("Saved scenario scenario to ")
    assert (studio.game / "scenario.yaml").read_text() == "description: run right\nreward: delta(p1_x)\n"
    assert not draft.exists()
    page.click("scenario-stop")
    page.said("Stopped the live reward.")


def test_the_page_asks_before_dropping_an_unsaved_edit(page, studio):
    page.open("scenario")
    until("the scenario", lambda: editor_text(page))
    saved = editor_text(page)
    type_scenario(page, "reward: delta(p1_x) * 2\n")
    until("the edit seen as unsaved", lambda: page.el("scenario-unsaved").is_displayed())
    page.click("scenario-discard")
    alert = page.driver.switch_to.alert
    assert "not saved" in alert.text or "unsaved" in alert.text
    alert.dismiss()  # keep it
    page.said("Kept your edit.")
    assert editor_text(page) == "reward: delta(p1_x) * 2\n"
    page.click("scenario-discard")
    page.driver.switch_to.alert.accept()
    page.said("Dropped the edit of scenario.")
    assert editor_text(page) == saved
    until("the draft gone", lambda: not (studio.data / "studio" / "drafts" / "Dasher-Genesis" / "scenario.yaml").exists())


# --- the other panels ------------------------------------------------------------------------------------


def test_watch_edits_a_field(page, studio):
    page.open("watch")
    row = until("the field p1_deaths", lambda: page.driver.find_element(By.CSS_SELECTOR, '#watch-rows tr[data-field="p1_deaths"]'))
    row.find_element(By.TAG_NAME, "button").click()
    for label, value in (("range low", "0"), ("range high", "99")):
        box = row.find_element(By.CSS_SELECTOR, f'input[aria-label="{label}"]')
        box.clear()
        box.send_keys(value)
    row.find_element(By.CSS_SELECTOR, 'button[type="submit"]').click()
    page.said("Wrote field p1_deaths (0xFF0038, |u1) into ")
    fields = yaml.safe_load((studio.game / "game.yaml").read_text())["fields"]
    assert fields["p1_deaths"] == {"address": 0xFF0038, "type": "|u1", "range": [0, 99]}
    until("the row back, with its range", lambda: "[0, 99]" in page.driver.find_element(
        By.CSS_SELECTOR, '#watch-rows tr[data-field="p1_deaths"]').text)  # fmt: skip


def hud_lives_pixel() -> tuple[int, int]:
    """A pixel of Dasher's HUD lives digit that a poke of the lives changes (3 -> 4), 2 frames after Zone1.Act1."""
    import numpy as np

    from retrokit.ramsearch import RamSearch

    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        start = search.emulator.get_state()
        search.step([], 2)
        before = search.screen().copy()
        search.emulator.set_state(start)
        search.poke(0xFF002B, 4)
        search.step([], 2)
        ys, xs = np.nonzero((search.screen() != before).any(axis=2))
    return int(xs[0]), int(ys[0])


def click_pixel(page: Page, x: int, y: int) -> None:
    """Click the console pixel (x, y) of the screen, wherever and however large the canvas is drawn."""
    canvas = page.el("screen")
    size = canvas.size
    scale = size["width"] / int(canvas.get_attribute("width"))
    dx = round((x + 0.5) * scale - size["width"] / 2)  # Selenium's offsets are from the element's centre
    dy = round((y + 0.5) * scale - size["height"] / 2)
    ActionChains(page.driver).move_to_element_with_offset(canvas, dx, dy).click().perform()


def test_click_to_find_names_the_lives_under_the_hud_digit(page):
    x, y = hud_lives_pixel()
    page.open("clickfind")
    page.pause()
    page.reset("Zone1.Act1")
    page.el("cf-range").click()
    page.type("cf-start", "0xFF0020")
    page.type("cf-length", "32")
    click_pixel(page, x, y)
    page.said(f"Looking for what draws ({x}, {y}).")
    until("the search to finish", lambda: "done in" in page.text("cf-state"))
    assert page.text("cf-state").startswith("32 of 32 cells poked")
    hits = {row.get_attribute("data-address"): row.text
            for row in page.driver.find_elements(By.CSS_SELECTOR, "#cf-rows tr")}  # fmt: skip
    assert "0xFF002B" in hits and "p1_lives" in hits["0xFF002B"]
    assert page.text("current-state") == "Zone1.Act1" and page.paused()  # the game was not moved
    page.shot("clickfind")


def test_ram_view_highlights_what_changes(page):
    page.open("ramview")
    page.resume()
    until("the grid", lambda: len(page.driver.find_elements(By.CSS_SELECTOR, "#ram-grid td")) == 256)
    # Dasher's frame counter (0xFF0004-7) changes every frame: its low byte is highlighted.
    until("a changed byte", lambda: "changed" in (page.driver.find_element(
        By.CSS_SELECTOR, '#ram-grid td[title="0xFF0007"]').get_attribute("class") or ""))  # fmt: skip
    cells = [td.text for td in page.driver.find_elements(By.CSS_SELECTOR, "#ram-grid td")[:16]]
    assert all(len(c) == 2 and int(c, 16) >= 0 for c in cells)
    page.shot("ramview")
    page.pause()


def test_record_and_replay_a_movie(page, studio):
    from retrokit.movie import read_bk2

    page.open("watch")
    page.pause()
    page.reset("Zone1.Act1")
    page.click("record")
    page.said("Recording the inputs from now")
    page.advance(60, Keys.ARROW_RIGHT)
    page.settled()
    ran_to = page.field("p1_x")
    page.type("movie-name", "run")
    page.click("record")
    line = page.said("Wrote 60 frames to ")
    made = Path(line.removeprefix("Wrote 60 frames to ").rstrip("."))
    assert made.name == "run.bk2" and made.is_relative_to(studio.game.parent.parent)
    movie = read_bk2(made)
    assert len(movie.frames) == 60 and movie.frames[10][0] != 0  # RIGHT held on pad 1

    page.reset("Zone1.Act2")  # somewhere else: the replay goes back to the movie's start state
    page.advance(1)
    page.settled()
    assert page.field("act") == "1"
    before = page.frame()
    page.driver.find_element(By.CSS_SELECTOR, '#movie-rows tr[data-movie="run"] button').click()
    page.said("Replaying run: 60 frames.")
    until("the movie's 60 frames", lambda: page.frame() >= before + 60 and page.paused())  # its end pauses
    page.settled()
    # Back in the movie's act (Zone1.Act1: act 0), where the recording took the player.
    assert (page.field("act"), page.field("p1_x")) == ("0", ran_to)


def test_a_new_game_from_a_rom_then_another_game(page, studio, tmp_path):
    """Last: the studio plays another game afterwards."""
    from runner_rom import write_runner_rom

    rom = write_runner_rom(tmp_path / "runner.bin")
    page.open("newgame")
    page.type("new-rom", str(rom))
    page.type("new-name", "Runner-Genesis")
    page.click("new-make")
    page.said("Made Runner-Genesis; the studio plays it now.")
    game_yaml = studio.data / "games" / "Runner-Genesis" / "game.yaml"
    assert yaml.safe_load(game_yaml.read_text())["system"] == "Genesis"
    assert (studio.data / "roms" / "Runner-Genesis" / "rom.md").read_bytes() == rom.read_bytes()
    # The page starts afresh on it.
    until("the page on Runner-Genesis", lambda: page.text("game-name") == "Runner-Genesis (Genesis)")
    until("it to run", lambda: page.text("run-state") == "running")  # the page resumed it after its reload

    page.tab("newgame")
    page.type("open-game", "Airstriker-Genesis")
    page.click("open-make")
    until("the page on Airstriker", lambda: page.text("game-name") == "Airstriker-Genesis (Genesis)")
