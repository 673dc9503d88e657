"""In a pipe or a log file, `validate` and `import` print lines, never a progress bar redrawn with carriage returns."""

from __future__ import annotations

from pathlib import Path

from childproc import run_cli

REPO = Path(__file__).resolve().parent.parent


def test_validate_prints_one_line_per_stage_into_a_pipe() -> None:
    child = run_cli(["validate", "Dasher-Genesis", "--frames", "5"], timeout=240)
    assert child.returncode == 0, child
    assert "\r" not in child.stderr, child.stderr[:500]
    stages = [line for line in child.stderr.splitlines() if line.startswith("Dasher-Genesis: ")]
    assert stages and stages[0].endswith("(1/" + stages[0].rsplit("/", 1)[1]), child.stderr
    assert len(stages) == int(stages[0].rsplit("/", 1)[1].rstrip(")"))  # every stage, once


def test_import_draws_no_bar_into_a_pipe(tmp_path: Path) -> None:
    roms = tmp_path / "roms"
    roms.mkdir()
    (roms / "dasher.md").write_bytes((REPO / "games" / "Dasher-Genesis" / "rom.md").read_bytes())
    child = run_cli(["import", str(roms), "--data-dir", str(tmp_path / "data")])
    assert child.returncode == 0, child
    assert "\r" not in child.stderr and "Searching" not in child.stderr, child.stderr
