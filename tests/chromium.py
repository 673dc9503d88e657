"""Headless Chromium for the studio's browser tests: Debian's ``chromium`` and ``chromium-driver``, through Selenium.

Importing this module skips the importing test module where either is missing.
"""

from __future__ import annotations

import contextlib
import shutil
import time
from collections.abc import Callable, Iterator

import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMEDRIVER = shutil.which("chromedriver")
WAIT = 120.0  # seconds: the machine running the suite may be loaded (a fresh studio takes tens)

pytest.importorskip("selenium", reason="selenium is not installed (pip install -e '.[test]')")
if CHROMIUM is None or CHROMEDRIVER is None:
    pytest.skip(
        "headless Chromium is not installed (Debian: apt-get install chromium chromium-driver; .ci/run does)",
        allow_module_level=True,
    )

from selenium import webdriver
from selenium.common.exceptions import NoAlertPresentException
from selenium.webdriver.chrome.service import Service


@contextlib.contextmanager
def chrome() -> Iterator[webdriver.Chrome]:
    """A headless Chromium of a fixed window size, keeping the page's console log; quit when the block ends."""
    options = webdriver.ChromeOptions()
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--window-size=1400,1000", "--force-device-scale-factor=1"):  # fmt: skip
        options.add_argument(argument)
    options.binary_location = CHROMIUM
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    try:
        yield driver
    finally:
        driver.quit()


def fresh(driver: webdriver.Chrome) -> webdriver.Chrome:
    """Make a browser that earlier tests used as a new one: no alert, a blank page, no cookies, an empty console log.

    One Chromium serves every browser test of a pytest process (tests/conftest.py's ``browser``); a new one for
    each module took seconds on a loaded machine. What a test leaves behind is what a new browser would not have.
    """
    try:
        driver.switch_to.alert.dismiss()  # a test that failed with a dialog open
    except NoAlertPresentException:
        pass
    driver.get("about:blank")
    driver.execute_cdp_cmd("Network.clearBrowserCookies", {})
    driver.get_log("browser")  # read, so the next test sees only its own page's messages
    return driver


def until(what: str, check: Callable[[], object], timeout: float = WAIT) -> object:
    """Wait for ``check()`` to return something true; fail saying ``what`` was awaited."""
    deadline = time.monotonic() + timeout
    while True:
        try:
            value = check()
        except Exception:  # an element not there yet  # noqa: BLE001
            value = None
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"waited {timeout:.0f} s for {what}")
        time.sleep(0.1)
