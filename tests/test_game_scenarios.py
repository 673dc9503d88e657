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
from retrokit import paths
from retrokit.errors import RetrokitError
from retrokit.games import find_game, list_games
from retrokit.scenario import load_scenario

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
