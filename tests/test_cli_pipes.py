"""In a pipe or a log file, `validate` and `import` print lines, never a progress bar redrawn with carriage returns."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

from childproc import run_cli

REPO = Path(__file__).resolve().parent.parent


def test_validate_prints_one_line_per_stage_into_a_pipe(tmp_path: Path) -> None:
    # Dasher with one solution movie of its six: every stage still runs (the movies stage replays one, 621
    # frames, not 5,700); the full game's validation is tests/test_validate.py's
    game = tmp_path / "Dasher-Genesis"
    shutil.copytree(REPO / "games" / "Dasher-Genesis", game)
    for movie in (game / "movies").glob("*.bk2"):
        if movie.stem != "Zone1.Act1":
            movie.unlink()
    yaml_text = (game / "game.yaml").read_text()
    kept = re.sub(r"(?m)^  Zone(?!1\.Act1:).*\{scenario: .*\n", "", yaml_text)
    assert kept.count("done_at:") == 1, kept
    (game / "game.yaml").write_text(kept)
    child = run_cli(["validate", str(game), "--frames", "5"], timeout=240)
    assert child.returncode == 0, child
    assert "\r" not in child.stderr, child.stderr[:500]
    stages = [line for line in child.stderr.splitlines() if line.startswith(f"{game}: ")]
    assert stages and stages[0].endswith("(1/" + stages[0].rsplit("/", 1)[1]), child.stderr
    assert len(stages) == int(stages[0].rsplit("/", 1)[1].rstrip(")"))  # every stage, once
    assert stages[-1].startswith(f"{game}: movies "), stages


def test_import_draws_no_bar_into_a_pipe(tmp_path: Path) -> None:
    roms = tmp_path / "roms"
    roms.mkdir()
    (roms / "dasher.md").write_bytes((REPO / "games" / "Dasher-Genesis" / "rom.md").read_bytes())
    child = run_cli(["import", str(roms), "--data-dir", str(tmp_path / "data")])
    assert child.returncode == 0, child
    assert "\r" not in child.stderr and "Searching" not in child.stderr, child.stderr
