"""docs/integrate.md's walkthroughs, run from the CLI as written, with the output they show.

The whole loop of issue 21, from a ROM no game knows to a benchmark, every
command's output compared with the text's; nothing is written by hand but the
scenario and the benchmark file:

- "Your own game, from a ROM": a header-patched Dasher (Genesis). Lives and x
  found by RAM search and saved with ranges; validate catches another game's state.
- "An Atari 2600 game, from ale-py's ROMs" (issue 29): ale-py's bare
  galaxian.bin, no header, 128 bytes of RAM at 0x80, a first state after the
  console's RESET switch; lives and a six-digit BCD score found by RAM search.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from walkthrough import GALAXIAN, NES, RUNNER, SHOWN_DATA, Step, Walkthrough

from retrokit.data.games import find_game


@pytest.fixture
def folders(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Path, Path]:
    data, work = tmp_path / "data", tmp_path / "work"
    work.mkdir()
    monkeypatch.setenv("RETROKIT_DATA", str(data))
    monkeypatch.delenv("RETROKIT_GAMES", raising=False)
    # validate's table fits the terminal's width, 120 columns when there is none (as in the text); a pytest-xdist
    # worker's inherited terminal would make it another.
    monkeypatch.setenv("COLUMNS", "120")
    monkeypatch.chdir(work)
    return work, data


def as_written(text: Walkthrough, work: Path, data: Path, capsys) -> list[Step]:
    """Run the walkthrough; check every command printed what the text shows, and every file shown is as written."""
    steps = list(text.run(work, data, capsys))
    wrong = [
        f"{text.document.name}:{s.line}: $ {s.command}\n--- shown\n{s.shown}\n--- printed\n{s.printed}"
        for s in steps
        if not s.matches()
    ]
    assert not wrong, "\n\n".join(wrong)
    shown = text.written()
    assert len(shown) == 1
    for path, content in shown:
        assert Path(path.replace(SHOWN_DATA, str(data))).read_text(encoding="utf-8").strip() == content.strip()
    return steps


def run_as_written(text: Walkthrough, work: Path, data: Path, capsys) -> list[Step]:
    """:func:`as_written`, and what the Genesis and Atari walkthroughs have in common (issue 21's loop by hand)."""
    steps = as_written(text, work, data, capsys)
    commands = [s.command.split()[1] for s in steps]
    for command in ("import", "new", "ramsearch", "validate", "evaluate"):
        assert command in commands
    lines = [s.command for s in steps]
    # issue 21: the CLI makes the first state and writes the fields' ranges; one command evaluates both agents
    assert any(line.startswith("retrokit ramsearch savestate ") and line.endswith(" --default") for line in lines)
    assert sum("--range" in line for line in lines if line.startswith("retrokit ramsearch save ")) == 2
    assert [c for c in lines if c.startswith("retrokit evaluate") and c.count("--agent") == 2]
    assert (work / "runs" / "report.md").is_file()
    return steps


def test_runner_genesis_runs_as_written(folders, capsys) -> None:
    work, data = folders
    lines = [s.command for s in run_as_written(RUNNER, work, data, capsys)]
    assert "retrokit ramsearch savestate Level1 --default" in lines
    assert RUNNER.by_hand() == [
        "# file: ~/.local/share/retrokit/games/Runner-Genesis/scenario.yaml",
        "# file: runner.yaml",
    ]
    game = data / "games" / "Runner-Genesis"
    assert (game / "game.yaml").is_file() and (game / "Level1.state").is_file()
    assert (data / "roms" / "Runner-Genesis" / "rom.md").is_file()
    assert RUNNER.written()[0][0] == "~/.local/share/retrokit/games/Runner-Genesis/game.yaml"


def test_galaxian_atari2600_runs_as_written(folders, capsys) -> None:
    work, data = folders
    lines = [s.command for s in run_as_written(GALAXIAN, work, data, capsys)]
    # a new user's path: the bare .bin told by its size, the console's RESET switch pressed before the first state
    assert "retrokit new galaxian.bin --name Galaxian-Atari2600" in lines
    assert any(line.startswith("retrokit ramsearch run --script ") and "RESET" in line for line in lines)
    assert GALAXIAN.by_hand() == [
        "# file: ~/.local/share/retrokit/games/Galaxian-Atari2600/scenario.yaml",
        "# file: galaxian.yaml",
    ]
    game = data / "games" / "Galaxian-Atari2600"
    assert (game / "Level1.state").is_file()
    assert (data / "roms" / "Galaxian-Atari2600" / "rom.a26").is_file()
    assert GALAXIAN.written()[0][0] == "~/.local/share/retrokit/games/Galaxian-Atari2600/game.yaml"
    # what the text says of the agents' episodes: JERK's ship lost at the right wall after 80 steps, each time
    episodes = {
        agent: [json.loads(line) for line in (work / "runs" / agent / "episodes.jsonl").read_text().splitlines()]
        for agent in ("jerk", "random")
    }
    assert {e["steps"] for e in episodes["jerk"]} == {80} and max(e["reward"] for e in episodes["jerk"]) == 30
    assert [(e["steps"], e["reward"]) for e in episodes["random"]] == [(200, 410), (200, 310)]


def test_nes_in_under_25_commands_runs_as_written(folders, capsys) -> None:
    """Issue 44: a new NES game from a bare ROM to evaluate, the fields found by `ramsearch find`, the benchmark written."""
    work, data = folders
    lines = [s.command for s in as_written(NES, work, data, capsys)]
    assert len(lines) < 25 and f"commands: {len(lines)}." in NES.section()[1]  # the count the text gives
    assert lines[:2] == ["retrokit import jumper.nes", "retrokit new jumper.nes --name Jumper-Nes"]
    finds = [line for line in lines if line.startswith("retrokit ramsearch find ")]
    assert len(finds) == 2 and all("--save --range" in line for line in finds)
    assert not [line for line in lines if line.startswith(("retrokit ramsearch filter", "retrokit ramsearch save "))]
    assert "retrokit benchmark new Jumper-Nes --budget 500 --max-episode-steps 300" in lines
    assert lines[-1].startswith("retrokit evaluate --benchmark jumper-nes.yaml --agent jerk --agent random")
    assert NES.by_hand() == ["# file: ~/.local/share/retrokit/games/Jumper-Nes/scenario.yaml"]  # all else: commands
    # the fields found are the cartridge's own, which its game.yaml names (the walk never reads it)
    hopper = find_game("Hopper-Nes").fields
    found = yaml.safe_load((data / "games" / "Jumper-Nes" / "game.yaml").read_text())["fields"]
    assert (found["lives"]["address"], found["x"]["address"]) == (hopper["p1_lives"].address, hopper["p1_x"].address)
    assert (found["lives"]["type"], found["x"]["type"]) == (hopper["p1_lives"].type, hopper["p1_x"].type)
    episodes = [json.loads(line) for line in (work / "runs" / "jerk" / "episodes.jsonl").read_text().splitlines()]
    assert episodes and all(e["level"] == "Jumper-Nes/Level1" for e in episodes)


def test_each_walkthrough_ends_where_the_next_section_starts() -> None:
    # the Genesis walkthrough runs up to the Atari one's heading, not into its commands
    runner, galaxian = ([line for line, _, _ in w.blocks()] for w in (RUNNER, GALAXIAN))
    assert runner and galaxian
    assert max(runner) < min(galaxian)
    assert not any("Galaxian" in text for _, _, text in RUNNER.blocks())
