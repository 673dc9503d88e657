"""The studio on every system we have a cartridge for (issue 29 §4): its buttons and keys, its RAM.

Parametrized over tools/cartridges.yaml as tests/test_systems.py is, in a real browser (headless
Chromium through Selenium, with tests/studiopage.py's server and page). One studio serves them all: it
opens each cartridge in turn by name, as its page's Open does, rather than a new studio for each, and the page is
loaded once for each cartridge:

- the page shows the system's buttons, each with a key, and the keys play the game: holding them
  moves it as the same buttons move our own emulator;
- the RAM view and click-to-find start on the system's RAM region (not the Genesis's 0xFF0000),
  and click-to-find over that region names the field under a pixel.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import yaml
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from studiopage import Page, Studio, click_pixel, running_studio, until  # first: it skips this module without Chromium

from retrokit.data.games import find_game
from retrokit.data.statecheck import load_state
from retrokit.host.emulator import Emulator
from retrokit.host.memory import FieldReader
from retrokit.ramsearch import RamSearch
from retrokit.ramsearch.ram import RamLayout
from retrokit.studio.play import key_map

REPO = Path(__file__).resolve().parent.parent
CARTRIDGES = list(yaml.safe_load((REPO / "tools" / "cartridges.yaml").read_text()))
# Frames the keys are held: in 20 every cartridge's pad field shows both buttons held and its player has moved
# (x and vx differ from no buttons' on all eight), and each frame is a screen the browser draws.
FRAMES = 20
VIEW = 256  # bytes the RAM view and click-to-find show by default

pytestmark = pytest.mark.timeout(600)

# The KeyboardEvent.code of a key, as Selenium types it.
SELENIUM_KEYS = {"ArrowUp": Keys.ARROW_UP, "ArrowDown": Keys.ARROW_DOWN, "ArrowLeft": Keys.ARROW_LEFT,
                 "ArrowRight": Keys.ARROW_RIGHT, "Enter": Keys.ENTER, "ShiftRight": Keys.SHIFT, "Backspace": Keys.BACKSPACE}  # fmt: skip


def selenium_key(code: str) -> str:
    return SELENIUM_KEYS.get(code) or code.removeprefix("Key").removeprefix("Digit").lower()


@pytest.fixture(scope="module")
def studio(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Studio]:
    games = [REPO / "games" / name for name in CARTRIDGES]
    with running_studio(tmp_path_factory.mktemp("studio"), games[0], tuple(games[1:])) as server:
        yield server


@pytest.fixture(scope="module", params=CARTRIDGES, ids=CARTRIDGES)
def cartridge(request, studio: Studio) -> str:
    """The cartridge the module's studio plays, opened by name (its tests run one after the other)."""
    studio.open_game(request.param)
    return request.param


@pytest.fixture(scope="module")
def page(chromium_session, studio: Studio, cartridge: str) -> Iterator[Page]:
    """The studio's page on the cartridge, loaded once for its tests: each goes to its panels by their tabs, as a
    user does. A load costs Chromium about a CPU-second (the page builds every panel, each asking the server), and
    loading the page for each panel took three a cartridge."""
    from chromium import fresh

    assert studio.game.name == cartridge
    page = Page(fresh(chromium_session), studio).open("watch")
    page.pause()  # each test steps the game itself; a running game is 60 screens a second for Chromium to draw
    yield page
    page.driver.get("about:blank")  # off the page before the studio opens the next cartridge


def fields_after(name: str, masks: int, frames: int) -> dict[str, int]:
    """Every field of a game's default state after ``frames`` frames holding ``masks`` on port 1, on our emulator."""
    game = find_game(name)
    emu = Emulator(game.system, game.require_rom(), ports=max(2, game.players))
    try:
        emu.set_state(load_state(game, game.state_path()))
        emu.run([masks, 0], frames)
        return FieldReader(list(game.fields.values()), emu.space).read()
    finally:
        emu.close()


def test_the_keys_play_the_systems_buttons(page: Page) -> None:
    game = find_game(page.studio.game.name)
    system = game.system
    if not page.el("watch").is_displayed():  # where the page opened, unless a test before went elsewhere
        page.tab("watch")
    assert page.text("game-name") == f"{game.name} ({system.name})"
    legend = page.legend()
    assert set(legend) == set(system.button_names), legend
    keys = key_map(system)
    assert set(keys.values()) == set(system.button_names), keys  # every button has a key, each its own
    # Hold RIGHT and a face button, paused, for FRAMES frames: the fields are what the same buttons give
    # on our own emulator, and not what no buttons give.
    held = ["RIGHT", *system.actions[-1][1]] if system.actions else ["RIGHT"]
    codes = {button: code for code, button in keys.items()}
    page.pause()
    page.reset(game.default_state)
    page.advance(FRAMES, *(selenium_key(codes[b]) for b in held))
    page.settled()
    shown = {name: int(page.field(name)) for name in game.fields}
    expected = fields_after(game.name, system.mask(held), FRAMES)
    assert shown == expected, {k: (shown[k], expected[k]) for k in shown if shown[k] != expected[k]}
    assert expected != fields_after(game.name, 0, FRAMES), "the buttons held changed nothing"
    assert not page.errors()


def pixel_of_a_field(name: str, start: int, size: int) -> tuple[str, int, int, int]:
    """A field in the system RAM whose poke (+1 on its first byte) changes a pixel 2 frames on, and that pixel."""
    game = find_game(name)
    with RamSearch(game) as search:
        emulator = search.emulator  # poked and run as click-to-find does (retrokit/studio/clickfind.py)
        begin = emulator.get_state()
        emulator.run(0, 2)
        before = emulator.screen().copy()
        for spec in sorted(game.fields.values(), key=lambda f: f.address):
            if not start <= spec.address < start + size:
                continue
            emulator.set_state(begin)
            emulator.poke(spec.address, (emulator.peek(spec.address) + 1) % 256)
            emulator.run(0, 2)
            ys, xs = np.nonzero((emulator.screen() != before).any(axis=2))
            if len(xs):
                return spec.name, spec.address, int(xs[0]), int(ys[0])
    raise AssertionError(f"no field of {name} in its system RAM changes the screen when poked")


def test_ram_view_and_click_to_find_start_on_the_systems_ram(page: Page) -> None:
    game = find_game(page.studio.game.name)
    emu = Emulator(game.system, game.require_rom())
    layout = RamLayout.of(emu.space)
    emu.close()
    start, size = next(region for region in layout.regions if region[0] == game.system.ram_base)
    length = min(VIEW, size)
    page.tab("ramview")
    # written as the CLI and game.yaml write this console's addresses (0x0000 on a NES, not Genesis's 0x000000)
    assert page.el("ram-start").get_attribute("value") == layout.format(start)
    assert int(page.el("ram-length").get_attribute("value")) == length
    until("the grid", lambda: len(page.driver.find_elements(By.CSS_SELECTOR, "#ram-grid td")) == length)
    first = page.driver.find_element(By.CSS_SELECTOR, "#ram-grid td").get_attribute("title")
    assert int(first, 16) == start
    # Click-to-find over VIEW bytes of the system RAM (where a field that draws a pixel is: Hopper-Nes keeps its
    # fields from 0x300) names that field under the pixel.
    field, address, x, y = pixel_of_a_field(game.name, start, size)
    page.tab("clickfind")
    page.pause()
    page.reset(game.default_state)
    assert page.el("cf-start").get_attribute("value") == layout.format(start)
    assert int(page.el("cf-length").get_attribute("value")) == length
    page.el("cf-range").click()
    if address >= start + length:  # past the default view: start the region at the field's row of 16
        page.type("cf-start", hex(min(address & ~0xF, start + size - length)))
    click_pixel(page, x, y)
    until("the search to finish", lambda: "done in" in page.text("cf-state"))
    assert page.text("cf-state").startswith(f"{length} of {length} cells poked")
    hits = {int(row.get_attribute("data-address"), 16): row.text
            for row in page.driver.find_elements(By.CSS_SELECTOR, "#cf-rows tr")}  # fmt: skip
    assert address in hits and field in hits[address], (field, hex(address), hits)
    assert not page.errors()
