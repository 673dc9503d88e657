"""Ctrl-C during a validation ends the studio at once and cleanly (issue 31 item 6, validation).

The studio used to wait for the validation to end (28 s), then print a
CancelledError traceback.
"""

from __future__ import annotations

import re
import shutil
import threading
import time
from pathlib import Path

import pytest
from studioproc import StudioProcess

DASHER = Path(__file__).resolve().parent.parent / "games" / "Dasher-Genesis"

pytestmark = pytest.mark.timeout(600)


def test_ctrl_c_during_a_validation_stops_the_studio_at_once(tmp_path):
    game = shutil.copytree(DASHER, tmp_path / "Dasher-Genesis")
    # A scenario that never ends an episode: validate's smoke run then plays all its frames on every state (minutes).
    scenario = game / "scenario.yaml"
    scenario.write_text(re.sub(r"^done: .*$", "done: frame < 0", scenario.read_text(), flags=re.MULTILINE))
    studio = StudioProcess(game, tmp_path / "data", tmp_path)
    try:
        long_one = None
        deadline = time.monotonic() + 400  # a short validation of ours may run first: a loaded machine takes minutes
        while True:  # under way once a second one is refused as running
            if long_one is None or not long_one.is_alive():  # (again, if our short one took the lock first)
                long_one = threading.Thread(
                    target=studio.request, args=("POST", "/api/validate", {"frames": 100_000}), daemon=True
                )
                long_one.start()
            status, body, _ = studio.request("POST", "/api/validate", {"frames": 1})
            if status >= 400 and "one is running" in str(body):
                break
            assert time.monotonic() < deadline, (status, body)
        asked = time.monotonic()
        err = studio.stop(timeout=60)
        took = time.monotonic() - asked
    finally:
        if studio.process.poll() is None:
            studio.process.kill()
    assert studio.process.returncode == 0, err
    assert "Traceback" not in err and "CancelledError" not in err, err
    assert took < 10, f"Ctrl-C took {took:.1f} s"  # the validation alone runs for minutes
