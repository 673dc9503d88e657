"""The README's main job: ``retrokit demo``, JERK against random on the Dasher benchmark."""

from __future__ import annotations

import json

from PIL import Image

from retrokit.cli import main

# 300 timesteps: JERK ends its first (long) episode on Zone2.Act2 within them, which the best GIF needs.
SMALL = ["demo", "--levels", "Zone2.Act2", "--timesteps", "300", "--workers", "1", "--no-progress"]


def test_demo_evaluates_jerk_and_random_and_saves_the_report_plots_and_a_gif(tmp_path, capsys, monkeypatch) -> None:
    from retrokit.host.buildhint import build_hint

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))  # no built core there: the wheel's runs
    out = tmp_path / "demo"
    assert main([*SMALL, "--out", str(out)]) == 0
    captured = capsys.readouterr()
    printed = captured.out
    for agent in ("jerk", "random"):  # the speed line `retrokit evaluate` prints, on stderr, per agent
        line = next(line for line in captured.err.splitlines() if line.startswith(f"{agent}: speed: "))
        # The Sonic protocol's time is named for the Sonic benchmark only (this is Dasher's).
        assert "env steps/s per level" in line and "the Sonic protocol" not in line
    # Then, once, the line that says how much faster Genesis envs step on the core retrokit build-core makes.
    assert captured.err.splitlines().count(build_hint("Genesis")) == 1 and "retrokit build-core" in build_hint("Genesis")
    table = printed[printed.index("level "):]
    assert "jerk" in table and "random" in table and "aggregate" in table and "Dasher-Genesis/Zone2.Act2" in table
    for agent in ("jerk", "random"):
        data = json.loads((out / agent / "summary.json").read_text())
        assert data["agent"] == agent and data["levels"]["Dasher-Genesis/Zone2.Act2"]["timesteps"] == 300
        assert (out / agent / "report.md").is_file() and (out / agent / "learning-curves.png").is_file()
    with Image.open(out / "scores.png") as image:
        assert image.format == "PNG"
    assert "| level | jerk | random |" in (out / "report.md").read_text()  # the same comparison as evaluate's
    with Image.open(out / "jerk-best.gif") as gif:
        assert gif.n_frames > 10 and gif.size == (320, 224)


def test_demo_never_replaces_an_earlier_demo(tmp_path, capsys) -> None:
    out = tmp_path / "demo"
    out.mkdir()
    (out / "mine.txt").write_text("mine")
    assert main([*SMALL, "--timesteps", "100", "--out", str(out)]) == 0
    assert (out / "mine.txt").read_text() == "mine" and sorted(p.name for p in out.iterdir()) == ["mine.txt"]
    assert (tmp_path / "demo-1" / "jerk" / "summary.json").is_file()


def test_demo_refuses_zero_timesteps(tmp_path, capsys) -> None:
    assert main([*SMALL, "--timesteps", "0", "--out", str(tmp_path / "demo")]) == 2
    err = capsys.readouterr().err
    assert "Expected --timesteps of 1 or more, got 0." in err and "--workers" not in err
