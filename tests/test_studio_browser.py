"""The studio's page in a real browser (issue 22's "Done when"), driven as a user would, on Dasher.

A real ``retrokit studio`` server runs in a child process on a free port, on a
copy of Dasher's game folder and an empty data folder in tmp_path; headless
Chromium (Debian's ``chromium`` and ``chromium-driver``, through Selenium)
opens the URL it prints (tests/studiopage.py), once for the module. Each test
is one step of the issue, going to its panel by its tab as a user does: open
the studio, validate, play with the keyboard, find the lives with the search
and add the field, save a state, play with a gamepad
(tests/test_studio_browser_panels.py has the scenario and the other panels).
The results are checked where they land: the screen, the RAM fields the page
shows, game.yaml, the .state file and its record.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import studiopage
import yaml
from dashercopy import dasher_copy
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import Select
from studiopage import (  # first: skips without Chromium
    canvas_colours,
    canvas_pixels,
    running_studio,
    until,
)

pytestmark = pytest.mark.timeout(600)


page_fixture = pytest.fixture(studiopage.module_page, scope="module", name="page")  # loaded once; tests go by tabs


@pytest.fixture(scope="module")
def studio(tmp_path_factory: pytest.TempPathFactory):
    """The module's studio, on a copy of Dasher with the states the steps play and no solution movies.

    Validate's step then checks 4 states in about 3 CPU-seconds, not Dasher's 9 states and 6 movies in 9;
    tests/test_validate.py validates Dasher as shipped.
    """
    root = tmp_path_factory.mktemp("studio")
    source = dasher_copy(root / "source", ("Zone1.Act1", "Zone1.Act1.2P", "Zone1.Act2", "Zone2.Act1"))
    with running_studio(root, source) as server:
        yield server


# --- the steps of the "Done when" -----------------------------------------------------------------


def test_open_the_studio_on_dasher(page):
    """The page as the module's fixture opened it (tests/studiopage.py's module_page, on the search tab)."""
    assert page.text("game-name") == "Dasher-Genesis (Genesis)"
    assert page.driver.title == "Dasher-Genesis · retrokit studio"
    screen = page.el("screen")
    assert (screen.get_attribute("width"), screen.get_attribute("height")) == ("320", "224")
    # The buttons are shown with their keys: the arrows are the D-pad, Enter is START.
    legend = page.legend()
    assert {"UP": "↑", "DOWN": "↓", "LEFT": "←", "RIGHT": "→", "START": "Enter"}.items() <= legend.items()
    assert set(legend) == {"B", "A", "MODE", "START", "UP", "DOWN", "LEFT", "RIGHT", "C", "Y", "X", "Z"}
    # Every panel started (a failing one says so on the message line).
    assert "could not start" not in page.message()
    assert not page.errors()
    page.resume()
    page.shot("play")
    # The search's listed candidates show live values while the game runs: cells change, and changed cells
    # flash (the page restarts their animations with one layout a message, not one per cell).
    first = page.driver.execute_script("return [...document.querySelectorAll('#search-rows td.live')].map(c => c.textContent)")
    assert len(first) == 100

    def flashing_changed() -> int:
        cells = page.driver.execute_script("return [...document.querySelectorAll('#search-rows td.live')].map("
                                           "c => [c.textContent, c.classList.contains('flash')])")
        return sum(flash and text != before for (text, flash), before in zip(cells, first, strict=True))

    until("several live values to change and flash", lambda: flashing_changed() >= 2)
    page.pause()  # the next steps play by frame advance or resume themselves


def test_validate(page):
    """Before the other steps change the game: Dasher's copy passes, its progress shown while it runs."""
    page.tab("validate")
    page.click("validate-run")
    until("its progress", lambda: page.text("validate-summary").startswith("checking Dasher-Genesis: "))
    page.said("Validated Dasher-Genesis: ")
    summary = page.text("validate-summary")
    assert summary.startswith("Dasher-Genesis: passed (") and " 0 failed, " in summary  # the copy of the game as shipped
    rows = page.driver.find_elements(By.CSS_SELECTOR, "#validate-rows tr")
    assert len(rows) > 5
    statuses = {row.get_attribute("class") for row in rows}
    assert statuses <= {"pass", "warn", "fail", "skip"} and "pass" in statuses
    page.shot("validate")


def at_the_start(page) -> int:
    """Put the player at Zone1.Act1's start, paused, then play on; return its x then.

    Read paused, where the Watch panel's values are those of the frame on the screen: read while the game runs,
    a loaded browser could show the values of a frame before the reset, where the player was elsewhere.
    """
    page.pause()
    page.reset("Zone1.Act1")
    page.advance(1)
    page.settled()
    return int(page.field("p1_x"))


def test_play_with_the_keyboard(page):
    page.tab("watch")
    x0 = at_the_start(page)
    frame0, pixels0 = page.frame(), canvas_pixels(page)
    page.resume()
    ActionChains(page.driver).key_down(Keys.ARROW_RIGHT, page.el("screen")).perform()
    until("the RIGHT button to light up", lambda: "held" in page.driver.find_element(
        By.CSS_SELECTOR, '#buttons [data-button="RIGHT"]').get_attribute("class"))  # fmt: skip
    until("the player to run right", lambda: int(page.field("p1_x")) > x0 + 20)
    ActionChains(page.driver).key_up(Keys.ARROW_RIGHT).perform()
    until("the screen to move with the player", lambda: page.frame() > frame0 and canvas_pixels(page) != pixels0)
    until("the frame number under it to run on", lambda: int(page.text("frame")) > frame0)  # a few times a second
    # Paused, a reset shows the state chosen (loading a state does not draw it: the server does).
    page.pause()
    page.reset("Zone2.Act1")
    until("Zone 2 on the screen", lambda: canvas_colours(page) > 4)
    # Frame advance runs exactly the frames asked for, paused.
    before = page.frame()
    page.advance(30)
    assert page.frame() == before + 30 and page.paused()
    assert page.text("frame") == str(before + 30)  # paused, the number shown is the screen's exactly
    # The speed menu reaches the server: its status comes back with it.
    Select(page.el("speed")).select_by_value("2")
    until("2x", lambda: page.text("speed-shown") == "2×")
    Select(page.el("speed")).select_by_value("1")
    until("1x", lambda: page.text("speed-shown") == "1×")


def test_find_the_lives_with_the_search_and_add_the_field(page, studio):
    """docs/ramsearch.md's walkthrough, in the page: 3 lives, run into the pit twice, the byte is found."""
    page.tab("search")
    page.pause()
    page.reset("Zone1.Act1")
    page.click("search-new")
    page.said("New search: 2,490,276 candidates.")

    def filter_(op: str, value: str = "") -> str:
        Select(page.el("search-op")).select_by_value(op)
        if value:
            page.type("search-value", value)
        page.click("search-apply")
        return page.said(f"{op}")

    assert filter_("equal", "3").startswith("equal 3: 2,490,276 -> ")
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
    assert page.text("search-count") != "15 candidates"
    page.click("search-redo")
    page.said("Redid decreased --than previous: 15 candidates.")
    page.type("poke-value", "9")
    page.click("poke")
    page.said("Poked 0xFF002B (|u1): it now reads 9.")
    until("9 lives in Watch", lambda: page.field("lives") == "9")


def test_find_a_field_with_one_button(page, studio):
    """Issue 44: Find plays what changes the lives and what keeps them, in turn, until one value is left, and adds it."""
    page.tab("search")
    page.pause()
    page.reset("Zone1.Act1")
    page.click("search-new")
    page.said("New search: 2,490,276 candidates.")
    before = studio.server.request("GET", "/api/status")[1]["frame"]  # the server's: the canvas may lag behind
    page.type("find-changes", "RIGHT*200")  # into the pit: a life lost
    Select(page.el("find-kind")).select_by_value("decreases")
    page.type("find-keeps", "_*130")  # the respawn
    page.type("find-name", "lives_found")
    page.el("find-save").click()
    page.type("field-lo", "0")
    page.type("field-hi", "9")
    page.click("find")
    said = page.said("Found lives_found: 0xFF002B |u1 (one value is left, read 36 ways). Wrote field lives_found "
                     "(0xFF002B, |u1, range [0, 9]) into ")  # fmt: skip
    assert said.endswith(f"{studio.game / 'game.yaml'}.")
    fields = yaml.safe_load((studio.game / "game.yaml").read_text())["fields"]
    assert fields["lives_found"] == {"address": 0xFF002B, "type": "|u1", "range": [0, 9]}
    rows = page.driver.find_elements(By.CSS_SELECTOR, "#search-rows tr")
    assert rows[0].get_attribute("data-address") == "0xFF002B" and rows[0].get_attribute("data-type") == "|u1"
    assert rows[0].find_elements(By.TAG_NAME, "td")[4].text.split() == ["3", "2", "2", "1", "1", "0"]
    # three rounds played, the last one's keeps cut short by the find: the screen is where the game now is
    until("the screen after the find", lambda: page.frame() == before + 3 * 200 + 2 * 130)
    assert page.el("field-address").get_attribute("value") == "0xFF002B"  # "add as field" is filled too
    # a mistake is refused before anything plays, with the script's caret
    page.type("find-changes", "(RIGHT*2")
    page.click("find")
    until("the script's error", lambda: "In the script at line 1, column 8: Expected" in page.message())
    assert studio.server.request("GET", "/api/status")[1]["frame"] == before + 860  # nothing played


def test_save_a_state(page, studio):
    from retrokit.data.states import read_state_file

    page.tab("search")
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


def test_play_with_a_gamepad(page):
    """The Gamepad API's standard layout: button 15 is the D-pad's right. Headless Chromium has no pad, so the page
    is given one through the API it reads (navigator.getGamepads), as a browser would report a real pad.

    Last: the pad stays plugged in the module's page (the page polls it every animation frame from then on)."""
    page.tab("watch")
    x0 = at_the_start(page)
    page.resume()
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
