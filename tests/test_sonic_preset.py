"""The Sonic benchmark preset, as far as it can be shown without the Sonic ROMs.

The registry, the split, the action sets and the missing-ROM message are
Sonic's own; the wrappers are shown working on a real env (Airstriker).
"""

from __future__ import annotations

import numpy as np
import pytest

import retrokit
from retrokit.data.games import find_game
from retrokit.envs import sonic
from retrokit.errors import InvalidArgumentError, RomNotFoundError, StateNotFoundError


def test_58_levels_split_47_train_11_test() -> None:
    levels, train, test = sonic.levels(), sonic.train_levels(), sonic.test_levels()
    assert len(levels) == 58 and len(train) == 47 and len(test) == 11
    assert set(train) | set(test) == set(levels) and not set(train) & set(test)
    counts = {game: sum(1 for g, _ in levels if g == game) for game in sonic.GAMES}
    assert counts == {"SonicTheHedgehog-Genesis": 17, "SonicTheHedgehog2-Genesis": 18, "SonicAndKnuckles3-Genesis": 23}


@pytest.mark.parametrize("level", sonic.test_levels(), ids=lambda level: f"{level[0].split('-')[0]}/{level[1]}")
def test_every_test_level_has_a_state(level: tuple[str, str]) -> None:
    game, state = level
    assert find_game(game).state_path(state).is_file()


@pytest.mark.parametrize("game", sonic.GAMES)
def test_each_game_has_the_contest_and_xpos_scenarios(game: str) -> None:
    scenarios = find_game(game).scenarios
    assert {"contest", "xpos"} <= set(scenarios)


def test_action_sets_are_the_papers() -> None:
    assert len(sonic.ACTIONS) == 7 and len(sonic.ACTIONS_WITH_NOOP) == 8
    assert sonic.ACTIONS_WITH_NOOP[0] == () and sonic.ACTIONS_WITH_NOOP[1:] == sonic.ACTIONS
    assert ("DOWN", "B") in sonic.ACTIONS  # the spin dash


def test_making_a_level_without_the_rom_says_how_to_import(monkeypatch: pytest.MonkeyPatch, tmp_path) -> None:
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path))
    with pytest.raises(RomNotFoundError) as info:
        sonic.make("SonicTheHedgehog-Genesis", "GreenHillZone.Act1")
    message = str(info.value)
    assert "retrokit import" in message
    assert find_game("SonicTheHedgehog-Genesis").sha1s[0] in message


@pytest.mark.parametrize(
    "game,state,error,message",
    [
        ("SonicTheHedgehog4-Genesis", "GreenHillZone.Act1", InvalidArgumentError, "Did you mean 'SonicTheHedgehog-Genesis'"),
        ("SonicTheHedgehog-Genesis", "GreenHilZone.Act1", StateNotFoundError, "Did you mean 'GreenHillZone.Act1'"),
    ],
    ids=["unknown-game", "unknown-level"],
)
def test_bad_level_names_suggest(game: str, state: str, error: type, message: str) -> None:
    with pytest.raises(error, match=message):
        sonic.make(game, state)


def test_discretizer_presses_each_combination() -> None:
    env = sonic.Discretizer(retrokit.make("Airstriker-Genesis", action_type="all"), sonic.ACTIONS_WITH_NOOP)
    assert env.action_space.n == 8
    system = env.unwrapped.emulator.system
    for index, combo in enumerate(sonic.ACTIONS_WITH_NOOP):
        bits = env.action(index)
        assert system.buttons_of(int(np.dot(bits, 1 << np.arange(12)))) == [b for b in system.buttons if b in combo]
    env.close()


def test_allow_backtracking_rewards_only_new_progress() -> None:
    # The env below reports these gains; the cumulative progress is 5, 3, 8, 8, 12.
    base = retrokit.make("Airstriker-Genesis")
    env = sonic.AllowBacktracking(base)
    env.reset(seed=0)
    gains = [5.0, -2.0, 5.0, 0.0, 4.0]
    out = []
    for gain in gains:
        env.unwrapped.step = lambda action, g=gain: (None, g, False, False, {})  # the wrapper sees this reward
        out.append(env.step(None)[1])
    assert out == [5.0, 0.0, 3.0, 0.0, 4.0]
    env.close()


@pytest.mark.parametrize("level", sonic.levels(), ids=lambda level: f"{level[0].split('-')[0]}/{level[1]}")
def test_every_level_is_ready_but_for_the_rom(level: tuple[str, str], monkeypatch: pytest.MonkeyPatch, tmp_path) -> None:
    from retrokit.data.states import read_state
    from retrokit.dsl.scenario import load_scenario

    game_name, state = level
    game = find_game(game_name)
    assert len(read_state(game.state_path(state))) == 1_036_288  # Genesis Plus GX's state size
    for scenario in ("contest", "xpos"):
        load_scenario(game.scenario_path(scenario), list(game.fields), game_dir=game.folders[0])
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path))
    with pytest.raises(RomNotFoundError, match=f"SHA-1 {game.sha1s[0]}.*retrokit import"):
        sonic.make(game_name, state)
