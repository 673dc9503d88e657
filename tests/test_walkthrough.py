"""docs/integrate.md's "Your own game, from a ROM", run from the CLI as written, with the output it shows.

The whole loop of issue 21 on a header-patched Dasher that no known game
matches: new game, first state, lives and x found by RAM search and saved
with ranges, a scenario, validate (which catches another game's state) and
an evaluation, every command's output compared with the text's.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import walkthrough


@pytest.fixture
def folders(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Path, Path]:
    data, work = tmp_path / "data", tmp_path / "runner"
    work.mkdir()
    monkeypatch.setenv("RETROKIT_DATA", str(data))
    monkeypatch.delenv("RETROKIT_GAMES", raising=False)
    monkeypatch.chdir(work)
    return work, data


def test_the_walkthrough_runs_as_written(folders, capsys) -> None:
    work, data = folders
    steps = list(walkthrough.run(work, data, capsys))
    wrong = [f"{walkthrough.DOCUMENT.name}:{s.line}: $ {s.command}\n--- shown\n{s.shown}\n--- printed\n{s.printed}"
             for s in steps if not s.matches()]
    assert not wrong, "\n\n".join(wrong)
    commands = [s.command.split()[1] for s in steps]
    for command in ("import", "new", "integrate", "ramsearch", "validate", "evaluate"):
        assert command in commands
    game = data / "games" / "Runner-Genesis"
    assert (game / "game.yaml").is_file() and (game / "Level1.state").is_file()
    assert (data / "roms" / "Runner-Genesis" / "rom.md").is_file()
