"""Writers that race on one game.yaml: every edit a command or a studio acknowledged is in the file after.

Each writer reads game.yaml, inserts its line and writes the file back; two
that read it at once would each write a file missing the other's line, so
every read-modify-write holds the folder's lock (retrokit.paths.locked).
The writers are real processes started together: 10 ``retrokit ramsearch
save`` commands (forked at once from one interpreter, tests/incli.py), and
two studios on one game adding 8 fields each.
"""

from __future__ import annotations

import os
import shutil
import threading
from pathlib import Path

import pytest
import yaml
from incli import retrokit_at_once, retrokit_in_process
from studioproc import StudioProcess

REPO = Path(__file__).resolve().parent.parent
DASHER = REPO / "games" / "Dasher-Genesis"

pytestmark = pytest.mark.timeout(600)


@pytest.fixture
def game(tmp_path: Path) -> Path:
    """A copy of Dasher's folder, found by name through RETROKIT_GAMES."""
    folder = tmp_path / "games" / "Dasher-Genesis"
    shutil.copytree(DASHER, folder)
    return folder


def fields_of(game: Path) -> dict:
    return yaml.safe_load((game / "game.yaml").read_text())["fields"]


def test_ten_ramsearch_saves_at_once_each_keep_their_field(tmp_path, game, monkeypatch):
    env = {**os.environ, "RETROKIT_GAMES": str(game.parent), "RETROKIT_DATA": str(tmp_path / "data")}
    monkeypatch.setenv("RETROKIT_GAMES", env["RETROKIT_GAMES"])  # for the session made in this process
    monkeypatch.setenv("RETROKIT_DATA", env["RETROKIT_DATA"])
    before = fields_of(game)
    # one type: a small session to load; what the saves race on is game.yaml
    made = retrokit_in_process(tmp_path, "ramsearch", "new", "Dasher-Genesis", "--state", "Zone1.Act1", "--types", "|u1")
    assert made.returncode == 0, made.stderr
    saves = [["ramsearch", "save", f"found_{i}", hex(0xFF0100 + i), "|u1"] for i in range(10)]
    warm = ("retrokit.ramsearch", "retrokit.commands.ramsearch", "retrokit.ramsearch.gamefile", "ruamel.yaml")
    for writer in retrokit_at_once(tmp_path, saves, env, warm=warm, prime=["ramsearch", "show"]):
        assert writer.returncode == 0 and writer.stdout.startswith("Wrote field"), writer.stderr
    after = fields_of(game)
    assert {name: after[name] for name in before} == before  # nothing of the author's lost
    assert sorted(set(after) - set(before)) == sorted(f"found_{i}" for i in range(10))
    assert all(after[f"found_{i}"] == {"address": 0xFF0100 + i, "type": "|u1"} for i in range(10))


def test_two_studios_on_one_game_keep_every_field_either_added(tmp_path, game):
    studios = [StudioProcess(game, tmp_path / "data", tmp_path) for _ in range(2)]
    failures: list[str] = []

    def add(studio: StudioProcess, which: int) -> None:
        for i in range(8):  # 8 each keep the two read-modify-writes overlapping throughout (15 took 2 s more)
            name = f"s{which}_field_{i}"
            status, body, _ = studio.request(
                "POST", "/api/search/field", {"name": name, "address": 0xFF0200 + 16 * which + i, "type": "|u1"}
            )
            if status != 200:
                failures.append(f"{name}: {status} {body}")

    try:
        threads = [threading.Thread(target=add, args=(studio, n)) for n, studio in enumerate(studios)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join(timeout=300)
    finally:
        errors = [studio.stop() for studio in studios]
    assert not failures, failures
    assert all("Traceback" not in err for err in errors), errors
    after = fields_of(game)
    added = {name: spec for name, spec in after.items() if "_field_" in name}
    assert len(added) == 16
    assert all(added[f"s{w}_field_{i}"]["address"] == 0xFF0200 + 16 * w + i for w in range(2) for i in range(8))
