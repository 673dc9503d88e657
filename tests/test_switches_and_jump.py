"""Console switches and the jump button: per-system facts of the descriptor, and the agents that use them.

A console switch (the 2600's SELECT and RESET, the Master System's PAUSE) ends or restarts a game, so
the default action groups hold none, and the random agent, JERK and validate's smoke run leave them
alone. JERK jumps with the system's jump button, or the scenario's, through any action type.
"""

from __future__ import annotations

import random
from pathlib import Path

import gymnasium
import numpy as np
import pytest
import yaml

import retrokit
from retrokit.benchmark.agents import random_agent
from retrokit.benchmark.jerk import Jerk
from retrokit.envs.actions import ACTION_TYPES, ActionMap
from retrokit.errors import DataFileError, InvalidArgumentError
from retrokit.host.systems import System, all_systems, get_system

REPO = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize("name", sorted(all_systems()))
def test_jump_and_start_are_buttons_and_no_default_group_holds_a_switch(name: str) -> None:
    system = get_system(name)
    assert system.jump in system.pad_buttons and system.start in system.button_names
    in_groups = {button for group in system.actions for combo in group for button in combo}
    assert system.jump in in_groups  # so JERK can press it with a discrete action too
    assert not in_groups & set(system.switches)


def test_the_2600_and_master_system_have_switches() -> None:
    assert get_system("Atari2600").switches == ("SELECT", "RESET")
    assert get_system("Sms").switches == ("PAUSE",)
    assert get_system("Atari2600").start == "RESET" and get_system("Atari2600").jump == "BUTTON"


def test_a_descriptor_naming_no_button_is_refused() -> None:
    with pytest.raises(DataFileError, match=r"its jump to be one of its buttons .* got 'C'"):
        System("X", "core", ("x",), 0, 1, ("B", None, "SELECT", "START"), jump="C")


@pytest.mark.parametrize("action_type", ACTION_TYPES)
@pytest.mark.parametrize("system", ["Atari2600", "Nes", "Genesis", "PCEngine"])
def test_press_gives_each_action_type_the_buttons_named(system: str, action_type: str) -> None:
    actions = ActionMap(get_system(system), action_type)
    combo = ["RIGHT", get_system(system).jump]
    assert actions.to_masks(actions.press(combo)) == [get_system(system).mask(combo)]


def test_press_names_the_combinations_a_discrete_action_can_make() -> None:
    with pytest.raises(InvalidArgumentError, match=r"one listed combination of each group .* got \['SELECT'\]"):
        ActionMap(get_system("Atari2600"), "discrete").press(["SELECT"])


class Recorder(gymnasium.Env):
    """An env that keeps the masks it was given, standing for a 2600 game's."""

    def __init__(self, action_type: str) -> None:
        self.actions = ActionMap(get_system("Atari2600"), action_type)
        self.action_space = self.actions.space
        self.observation_space = gymnasium.spaces.Discrete(1)
        self.jump_button = "BUTTON"
        self.masks: list[int] = []

    def reset(self, *, seed=None, options=None):
        return 0, {}

    def step(self, action):
        self.masks += self.actions.to_masks(action)
        if len(self.masks) >= 2000:
            raise StopIteration  # the budget, as the evaluator's monitor ends a play
        return 0, float(len(self.masks) % 7 == 0), False, False, {}


def test_the_random_agent_leaves_the_switches_alone() -> None:
    env = Recorder("all")
    env.action_space.seed(0)
    with pytest.raises(StopIteration):
        random_agent(env, 2000, 0)
    held = np.bitwise_or.reduce(env.masks)
    assert held & get_system("Atari2600").mask(["BUTTON", "UP", "RIGHT"]) and not held & get_system("Atari2600").switch_mask


@pytest.mark.parametrize("action_type", ACTION_TYPES)
def test_jerk_runs_with_every_action_type_and_jumps_with_the_systems_button(action_type: str) -> None:
    env = Recorder(action_type)
    with pytest.raises(StopIteration):
        Jerk(env, 2000, random.Random(0)).play()
    atari = get_system("Atari2600")
    assert atari.mask(["RIGHT", "BUTTON"]) in env.masks and not np.bitwise_or.reduce(env.masks) & atari.switch_mask


def test_jerk_takes_the_scenarios_jump_button(tmp_path: Path) -> None:
    scenario = yaml.safe_load((REPO / "games" / "Dasher-Genesis" / "scenario.yaml").read_text())
    (tmp_path / "jump_c.yaml").write_text(yaml.safe_dump({**scenario, "jump": "C"}))
    env = retrokit.make("Dasher-Genesis", scenario=tmp_path / "jump_c.yaml", action_type="discrete")
    try:
        assert env.jump_button == "C" and retrokit.make("Dasher-Genesis").jump_button == "B"
        jerk = Jerk(env, 100, random.Random(0))
        assert env.actions.to_masks(jerk.moves[False, True]) == [env.emulator.system.mask(["RIGHT", "C"])]
    finally:
        env.close()


@pytest.mark.parametrize("name", sorted(all_systems()))
def test_the_studio_keys_give_enter_to_the_start_button_and_a_key_to_every_button(name: str) -> None:
    from retrokit.studio.play import key_map, pad_map

    system = get_system(name)
    keys = key_map(system)
    assert keys["Enter"] == system.start and pad_map(system)["9"] == system.start
    assert set(keys.values()) == set(system.button_names)
    assert {keys[k] for k in ("ArrowUp", "ArrowDown", "ArrowLeft", "ArrowRight")} == {"UP", "DOWN", "LEFT", "RIGHT"}
