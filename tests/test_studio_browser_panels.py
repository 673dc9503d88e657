"""The studio's page in a real browser, its other panels: scenario, watch, click to find, RAM view, movies, new game.

As tests/test_studio_browser.py (the issue's first steps), on a studio of its
own: a real ``retrokit studio`` child process on a copy of Dasher, and the
session's headless Chromium driving its page as a user would: the page is loaded
once for the module and each test goes to its panel by its tab (a test about a
reload loads it again itself).
"""

from __future__ import annotations

from pathlib import Path

import pytest
import studiopage
import yaml
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from studiopage import (  # first: it skips this module where Chromium is missing
    click_pixel,
    editor_text,
    type_scenario,
    until,
)

pytestmark = pytest.mark.timeout(600)


studio_fixture, page_fixture = studiopage.fixtures()


def test_write_a_scenario_and_watch_its_reward_live(page, studio):
    page.tab("scenario")
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
    page.tab("scenario")
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
    page.tab("watch")
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


def test_click_to_find_names_the_lives_under_the_hud_digit(page):
    x, y = hud_lives_pixel()
    page.tab("clickfind")
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
    page.tab("ramview")
    page.resume()
    until("the grid", lambda: len(page.driver.find_elements(By.CSS_SELECTOR, "#ram-grid td")) == 256)
    # Dasher's frame counter (0xFF0004-7) changes every frame: its low byte is highlighted.
    until("a changed byte", lambda: "changed" in (page.driver.find_element(
        By.CSS_SELECTOR, '#ram-grid td[title="0xFF0007"]').get_attribute("class") or ""))  # fmt: skip
    # Read in one script: the grid is redrawn as the game runs, and cells found in one call may be gone in the next.
    cells = page.driver.execute_script(
        "return Array.from(document.querySelectorAll('#ram-grid td'), (td) => td.innerText).slice(0, 16);"
    )
    assert all(len(c) == 2 and int(c, 16) >= 0 for c in cells)
    page.shot("ramview")
    page.pause()


def test_record_and_replay_a_movie(page, studio):
    from retrokit.movie import read_bk2

    page.tab("watch")
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
    page.tab("newgame")
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
