"""Every scenario of every known game compiles, and a folder of scenarios alone adds to a game found elsewhere.

The wheel's Lua-scripted scenarios are replaced by files of the same name in
``games/<Game>/``, folders that hold nothing else: the game's data file, ROM
hashes and states still come from the wheel.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import retrokit
from retrokit import cli, paths
from retrokit.data.games import find_game, list_games
from retrokit.dsl.scenario import load_scenario
from retrokit.errors import RetrokitError, ScenarioError

REPO = Path(__file__).resolve().parents[1]


def test_every_scenario_of_every_game_compiles() -> None:
    """All 1,043 scenario files of stable-retro 1.0 and games/ (Lua ones through their rewrites)."""
    refused, count = [], 0
    for game in list_games():
        for name, path in game.scenarios.items():
            count += 1
            try:
                load_scenario(path, list(game.fields))
            except RetrokitError as exc:
                refused.append(f"{game.name} {name}: {str(exc).splitlines()[0]}")
    assert count >= 1043
    assert refused == []


@pytest.mark.parametrize("name", ["1942-Nes", "Tennis-Atari2600", "SonicTheHedgehogCustomKevin-Genesis"])
def test_scenario_folder_shadows_the_wheel_and_keeps_its_data(name: str) -> None:
    game = find_game(name)
    ours, wheel = game.folders
    assert ours == REPO / "games" / name and not (ours / "data.json").exists()
    assert wheel.parent.parent == paths.wheel_dir() / "data"
    assert game.info.source == wheel / "data.json"
    assert game.sha1s == tuple((wheel / "rom.sha").read_text().split())
    assert game.states and all(game.state_path(s).parent == wheel for s in game.states)
    scenario = "contest" if "Sonic" in name else "scenario"
    assert game.scenario_path(scenario) == ours / f"{scenario}.yaml"
    assert "scripts" in json.loads((wheel / f"{scenario}.json").read_text())  # the Lua one it replaces


def test_scenario_folder_on_the_real_emulator(tmp_path, monkeypatch) -> None:
    """A folder with only a scenario for Airstriker: listed once, wheel ROM and state used, its reward computed."""
    (tmp_path / "Airstriker-Genesis").mkdir()
    (tmp_path / "Airstriker-Genesis" / "scenario.yaml").write_text("reward: delta(score) * 2\ndone: lives == 0\n")
    (tmp_path / "Airstriker-Genesis" / "survive.yaml").write_text("reward: 1\ndone: lives < initial(lives)\n")
    (tmp_path / "NoSuchGame-Genesis").mkdir()  # scenarios for no known game: not a game
    (tmp_path / "NoSuchGame-Genesis" / "scenario.yaml").write_text("reward: 1\n")
    monkeypatch.setenv(paths.GAMES_ENV, str(tmp_path))
    assert [g.name for g in list_games("Airstriker")] == ["Airstriker-Genesis"]
    assert list_games("NoSuchGame") == []
    game = find_game("Airstriker-Genesis")
    assert game.folders[0] == tmp_path / "Airstriker-Genesis" and game.rom_path() is not None
    assert set(game.scenarios) == {"scenario", "survive"}
    env = retrokit.make("Airstriker-Genesis", obs_type="ram", frameskip=4)
    try:
        _, info = env.reset(seed=0)
        score, total = info["score"], 0.0
        for step in range(300):  # tap fire (B), so that the ship shoots and scores
            _, reward, terminated, _, info = env.step(env.actions.press(["B"] if step % 8 < 4 else []))
            total += reward
            if terminated:
                break
        assert info["score"] > score and total == 2 * (info["score"] - score)
    finally:
        env.close()


# --- retrokit games: the scenarios column ------------------------------------------------------------


def games_command(capsys, *argv: str) -> tuple[int, str]:
    status = cli.main(["games", *argv])
    out, err = capsys.readouterr()
    assert err == ""
    return status, out


def line_of(out: str, game: str) -> str:
    return next(line for line in out.splitlines() if line.startswith(game + " "))


def test_games_command_says_every_scenario_compiles(capsys, monkeypatch, tmp_path) -> None:
    monkeypatch.setenv(paths.DATA_ENV, str(tmp_path))
    status, out = games_command(capsys, "Atari2600")
    assert status == 0
    assert "scenarios ok" in line_of(out, "Tennis-Atari2600")  # Lua in the wheel, ours in games/
    assert all("scenarios ok" in line for line in out.splitlines()[:-1])
    assert "does not compile" not in out.splitlines()[-1]


@pytest.mark.parametrize(
    "name,text",
    [("typo.yaml", "reward: delta(scroe)\n"), ("lua.json", '{"reward": {"script": "lua:f"}, "scripts": ["f.lua"]}'),
     ("binary.json", b"\x00\xff\xfe garbage"), ("binary.yaml", b"\xff\xfe\x00reward"), ("list.yaml", "- 1\n- 2\n")],
    ids=["unknown_field", "lua_script", "binary_json", "binary_yaml", "not_a_mapping"],
)
def test_games_command_names_scenarios_that_do_not_compile(capsys, monkeypatch, tmp_path, name: str, text) -> None:
    (tmp_path / "games" / "Airstriker-Genesis").mkdir(parents=True)
    target = tmp_path / "games" / "Airstriker-Genesis" / name
    target.write_bytes(text) if isinstance(text, bytes) else target.write_text(text)
    monkeypatch.setenv(paths.GAMES_ENV, str(tmp_path / "games"))
    monkeypatch.setenv(paths.DATA_ENV, str(tmp_path / "data"))
    status, out = games_command(capsys, "Airstriker")
    assert status == 0
    line = line_of(out, "Airstriker-Genesis")
    assert f"scenarios refused: {Path(name).stem}  states: Level1*" in line and "ROM bundled" in line
    assert out.splitlines()[-1].startswith("1 game shown; 1 of 1 have their ROM; 1 shown has a scenario that does not compile.")


def test_games_command_game_without_scenarios(capsys, monkeypatch, tmp_path) -> None:
    folder = tmp_path / "games" / "Plain-Genesis"
    folder.mkdir(parents=True)
    (folder / "data.json").write_text('{"info": {"lives": {"address": 16712282, "type": ">u2"}}}')
    (folder / "rom.sha").write_text("0" * 40 + "\n")
    monkeypatch.setenv(paths.GAMES_ENV, str(tmp_path / "games"))
    monkeypatch.setenv(paths.DATA_ENV, str(tmp_path / "data"))
    status, out = games_command(capsys, "Plain-Genesis")
    assert status == 0 and "ROM missing   scenarios none  states: (none)" in line_of(out, "Plain-Genesis")


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_a_scenario_that_is_not_utf8_is_refused_with_a_message(tmp_path, suffix: str) -> None:
    path = tmp_path / f"scenario{suffix}"
    path.write_bytes(b"reward: 1 # caf\xe9\n")  # Latin-1, as an old editor may save it
    with pytest.raises(ScenarioError, match=r"expected UTF-8 text, got the byte 0xe9") as info:
        load_scenario(path, ["x"])
    assert (info.value.line, info.value.column) == (1, 16)  # type: ignore[attr-defined]
