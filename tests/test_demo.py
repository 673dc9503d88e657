"""The README's main job: ``retrokit demo`` on the bundled test cartridge."""

from __future__ import annotations

from PIL import Image

from retrokit.cli import main


def test_demo_plays_and_saves_a_gif_and_a_png(tmp_path, capsys) -> None:
    assert main(["demo", "--episodes", "2", "--max-steps", "60", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "mean score" in out and out.count("done") + out.count("time limit") == 2
    header = next(line for line in out.splitlines() if line.lstrip().startswith("episode"))
    assert header.split()[:3] == ["episode", "reward", "steps"]  # the scenario's reward, not the game's score
    gif = Image.open(tmp_path / "Dasher-Genesis.gif")
    assert gif.n_frames > 5 and gif.size == (320, 224)
    assert Image.open(tmp_path / "Dasher-Genesis.png").size == (320, 224)


def test_demo_never_replaces_earlier_pictures(tmp_path, capsys) -> None:
    mine = tmp_path / "Dasher-Genesis.gif"
    mine.write_bytes(b"mine")
    assert main(["demo", "--episodes", "1", "--max-steps", "20", "--out", str(tmp_path)]) == 0
    assert mine.read_bytes() == b"mine"
    assert (tmp_path / "Dasher-Genesis-1.gif").is_file() and (tmp_path / "Dasher-Genesis-1.png").is_file()


def test_demo_refuses_zero_episodes(tmp_path, capsys) -> None:
    assert main(["demo", "--episodes", "0", "--out", str(tmp_path)]) == 2
    assert "--episodes and --max-steps of 1 or more" in capsys.readouterr().err
