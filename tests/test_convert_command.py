"""``retrokit convert``: Gym Retro scenario.json to YAML that loads and agrees."""

from __future__ import annotations

from retrokit.cli import main
from retrokit.data.games import find_game
from retrokit.dsl.scenario import load_scenario


def test_convert_writes_yaml_that_scores_like_the_json(tmp_path, capsys) -> None:
    game = find_game("Airstriker-Genesis")
    source = game.scenario_path("scenario")
    out = tmp_path / "scenario.yaml"
    assert main(["convert", str(source), str(out)]) == 0
    fields = list(game.fields)
    runs = [load_scenario(path, fields).start() for path in (source, out)]
    for run in runs:
        run.reset({"score": 0, "lives": 3, "gameover": 0})
    for values in ({"score": 10, "lives": 3, "gameover": 0}, {"score": 30, "lives": 0, "gameover": 1}):
        results = [run.step(values, 4, 1) for run in runs]
        assert results[0] == results[1]
    assert results[0][1] is True  # lives zero and gameover one: done


def test_convert_never_replaces_a_file_unasked(tmp_path, capsys) -> None:
    source = find_game("Airstriker-Genesis").scenario_path("scenario")
    out = tmp_path / "mine.yaml"
    out.write_text("# my own\n")
    assert main(["convert", str(source), str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--force" in err and "--overwrite" not in err and out.read_text() == "# my own\n"
    assert main(["convert", str(source), str(out), "--force"]) == 0
    assert "reward" in out.read_text()
    out.write_text("# my own\n")
    assert main(["convert", str(source), str(out), "--overwrite"]) == 0  # the old word, kept as a hidden alias
    assert "reward" in out.read_text()


def test_convert_prints_without_out(capsys) -> None:
    source = find_game("Airstriker-Genesis").scenario_path("scenario")
    assert main(["convert", str(source)]) == 0
    assert "done" in capsys.readouterr().out
