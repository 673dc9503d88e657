"""A fast start: ``import retrokit`` and ``retrokit --help`` import nothing heavy, and the Gymnasium ids still exist.

Each check runs in a fresh Python, where ``sys.modules`` shows what an import
pulled in. The ids are registered when Gymnasium is imported (at once if it
already is), from an index of the game folders kept in the data folder, which
must follow every change of those folders. tools/bench_startup.py times it.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
DASHER = REPO / "games" / "Dasher-Genesis"
# What `import retrokit` and `retrokit --help` must not import: each costs tens to hundreds of milliseconds.
HEAVY = (
    "gymnasium", "numpy", "jsonschema", "yaml", "matplotlib", "starlette", "uvicorn", "ray", "cv2", "pettingzoo",
    "retrokit.native._host", "retrokit.data.games", "retrokit.envs.env",
)  # fmt: skip


def run_python(code: str, env: dict[str, str] | None = None) -> str:
    """Run ``code`` in a fresh interpreter; return its stdout (the test fails with its stderr if it fails)."""
    done = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True, text=True, timeout=300, env={**os.environ, **(env or {})}, cwd=REPO, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return done.stdout


def heavy_after(statement: str) -> list[str]:
    out = run_python(f"import json, sys\n{statement}\nprint(json.dumps(sorted(m for m in {HEAVY!r} if m in sys.modules)))")
    return json.loads(out.strip().splitlines()[-1])  # after what the statement printed


def test_import_retrokit_imports_nothing_heavy() -> None:
    assert heavy_after("import retrokit") == []


def test_the_help_of_the_command_imports_nothing_heavy() -> None:
    statement = "from retrokit.cli import main\ntry:\n    main(['--help'])\nexcept SystemExit:\n    pass"
    assert heavy_after(statement) == []


def test_the_check_sees_a_heavy_import() -> None:
    """The check itself can fail: a module that imports numpy shows up."""
    assert "numpy" in heavy_after("import retrokit\nimport retrokit.host.memory")


EXPECTED_IDS = """
    import json
    from retrokit.data.games import list_games
    from retrokit.data.sonic_levels import levels
    from retrokit.envs.registration import game_id, level_id
    games = {game_id(g.name): {"entry_point": "retrokit.envs.env:make", "game": g.name} for g in list_games()}
    sonic = {level_id(g, s): {"entry_point": "retrokit.envs.sonic:make", "game": g, "state": s} for g, s in levels()}
    print(json.dumps({**games, **sonic}))
"""
REGISTERED_IDS = """
    import json, sys
    {imports}
    print(json.dumps({{
        i: {{"entry_point": s.entry_point, **s.kwargs}} for i, s in gymnasium.registry.items() if i.startswith("retrokit/")
    }}))
"""


@pytest.mark.parametrize(
    "imports", ["import retrokit, gymnasium", "import gymnasium, retrokit"], ids=["retrokit-first", "gymnasium-first"]
)
def test_every_game_and_sonic_level_is_registered_as_before(imports: str, tmp_path) -> None:
    env = {"RETROKIT_DATA": str(tmp_path)}
    expected = json.loads(run_python(EXPECTED_IDS, env))
    assert len(expected) >= 1089 and "retrokit/Dasher-Genesis-v0" in expected
    for attempt in ("made", "from the index"):
        registered = json.loads(run_python(REGISTERED_IDS.format(imports=imports), env))
        assert registered == expected, attempt
    assert (tmp_path / "cache" / "gymnasium-ids.json").is_file()


def registered_games(env: dict[str, str]) -> set[str]:
    code = REGISTERED_IDS.format(imports="import retrokit, gymnasium")
    return {i for i, spec in json.loads(run_python(code, env)).items() if spec["entry_point"].endswith("env:make")}


def test_the_index_follows_the_game_folders(tmp_path) -> None:
    games = tmp_path / "games"
    games.mkdir()
    env = {"RETROKIT_DATA": str(tmp_path / "data"), "RETROKIT_GAMES": str(games)}
    before = registered_games(env)
    assert "retrokit/Mine-Genesis-v0" not in before
    (games / "Mine-Genesis").mkdir()  # a folder with no data file yet is no game
    assert registered_games(env) == before
    shutil.copy(DASHER / "game.yaml", games / "Mine-Genesis" / "game.yaml")  # changes its folder, not the search folder
    assert registered_games(env) == before | {"retrokit/Mine-Genesis-v0"}
    (games / "Mine-Genesis" / "game.yaml").unlink()
    assert registered_games(env) == before


def test_an_index_of_the_same_folders_is_trusted(tmp_path) -> None:
    """The index is what the ids come from while the folders are as it recorded (so it is what saves the time)."""
    env = {"RETROKIT_DATA": str(tmp_path)}
    registered_games(env)
    cache = tmp_path / "cache" / "gymnasium-ids.json"
    kept = json.loads(cache.read_text())
    kept["games"].append("Recorded-Genesis")
    cache.write_text(json.dumps(kept))
    assert "retrokit/Recorded-Genesis-v0" in registered_games(env)
    cache.write_text("{not json")  # a damaged index is made again
    assert "retrokit/Recorded-Genesis-v0" not in registered_games(env)
