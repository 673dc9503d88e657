"""docs/integrate.md's "Your own game, from a ROM", run from the CLI as written, with the output it shows.

The whole loop of issue 21 on a header-patched Dasher that no known game
matches: new game, first state saved from a RAM search, lives and x found by
RAM search and saved with ranges, a scenario, validate (which catches another
game's state) and one evaluation of two agents, every command's output
compared with the text's. Nothing is written by hand but the scenario and
the benchmark file.
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
    # validate's table fits the terminal's width, 120 columns when there is none (as in the text); a pytest-xdist
    # worker's inherited terminal would make it another.
    monkeypatch.setenv("COLUMNS", "120")
    monkeypatch.chdir(work)
    return work, data


def test_the_walkthrough_runs_as_written(folders, capsys) -> None:
    work, data = folders
    steps = list(walkthrough.run(work, data, capsys))
    wrong = [f"{walkthrough.DOCUMENT.name}:{s.line}: $ {s.command}\n--- shown\n{s.shown}\n--- printed\n{s.printed}"
             for s in steps if not s.matches()]
    assert not wrong, "\n\n".join(wrong)
    commands = [s.command.split()[1] for s in steps]
    for command in ("import", "new", "ramsearch", "validate", "evaluate"):
        assert command in commands
    lines = [s.command for s in steps]
    # issue 21: the CLI makes the first state and writes the fields' ranges; one command evaluates both agents
    assert "retrokit ramsearch savestate Level1 --default" in lines
    assert sum("--range" in line for line in lines if line.startswith("retrokit ramsearch save ")) == 2
    assert [c for c in lines if c.startswith("retrokit evaluate") and c.count("--agent") == 2]
    text = walkthrough.DOCUMENT.read_text(encoding="utf-8")
    by_hand = [body.partition("\n")[0] for _, language, body in walkthrough.blocks(text)
               if language == "yaml" and body.startswith(("# file: ", "# append to: "))]
    assert by_hand == ["# file: ~/.local/share/retrokit/games/Runner-Genesis/scenario.yaml", "# file: runner.yaml"]
    game = data / "games" / "Runner-Genesis"
    assert (game / "game.yaml").is_file() and (game / "Level1.state").is_file()
    assert (data / "roms" / "Runner-Genesis" / "rom.md").is_file()
    assert (work / "runs" / "report.md").is_file()
    # the game.yaml the text says the commands left
    written = "# written by the commands above: ~/.local/share/retrokit/games/Runner-Genesis/game.yaml\n"
    shown = [body for _, language, body in walkthrough.blocks(text) if language == "yaml" and body.startswith(written)]
    assert len(shown) == 1
    assert (game / "game.yaml").read_text(encoding="utf-8").strip() == shown[0][len(written):].strip()
