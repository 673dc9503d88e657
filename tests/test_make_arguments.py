"""What make() and step() are given is checked: retrokit errors, never raw TypeError or silent misuse.

Issue 13, faults 13 (out-of-range discrete actions), 14 (frameskip values
that wrap in the native host; numpy integers) and 15 (wrongly typed
arguments, an off-screen crop, a misspelled keyword), and the versioned
Gymnasium ids.
"""

from __future__ import annotations

import enum
import inspect
import re

import gymnasium
import numpy as np
import pytest

import retrokit
from retrokit.data.games import find_game
from retrokit.envs import sonic
from retrokit.envs.env import RetroEnv
from retrokit.envs.options import OPTIONS
from retrokit.errors import InvalidArgumentError, RomNotFoundError, UnknownNameError

AIRSTRIKER = "Airstriker-Genesis"
DASHER = "Dasher-Genesis"


# --- fault 13: actions outside the action space ----------------------------------------------


def _airstriker(action_type: str):
    env = retrokit.make(AIRSTRIKER, action_type=action_type)
    env.reset(seed=0)
    yield env
    env.close()


@pytest.fixture(scope="module")
def discrete_env():
    yield from _airstriker("discrete")


@pytest.fixture(scope="module")
def multi_discrete_env():
    yield from _airstriker("multi_discrete")


@pytest.mark.parametrize(
    "action,message",
    [
        pytest.param("n", "from 0 to", id="one_past_the_end"),
        pytest.param("n*5", "from 0 to", id="far_past_the_end"),
        pytest.param(-1, "from 0 to", id="negative"),
        pytest.param(1.5, "whole number", id="float"),
        pytest.param(True, "whole number", id="bool"),
        pytest.param("3", "whole number", id="string"),
        pytest.param(np.array([1, 2]), "whole number", id="two_values"),
    ],
)
def test_discrete_action_out_of_range_is_refused(discrete_env, action: object, message: str) -> None:
    n = discrete_env.action_space.n
    action = {"n": n, "n*5": n * 5}.get(action, action) if isinstance(action, str) else action
    with pytest.raises(InvalidArgumentError, match=message):
        discrete_env.step(action)


@pytest.mark.parametrize("form", [int, np.int64, np.uint8, lambda a: np.array(a), lambda a: np.array([a])],
                         ids=["int", "int64", "uint8", "0d_array", "1_element_array"])
def test_every_discrete_action_in_range_is_accepted(discrete_env, form) -> None:
    for action in (0, discrete_env.action_space.n - 1):
        discrete_env.step(form(action))


@pytest.mark.parametrize(
    "change,message",
    [
        pytest.param(lambda a, n: np.where(np.arange(a.size) == 0, n[0], a), "choice 0", id="first_choice_past_the_end"),
        pytest.param(lambda a, n: np.where(np.arange(a.size) == a.size - 1, -1, a), "choice", id="negative_choice"),
        pytest.param(lambda a, n: a[:-1], "whole numbers", id="too_short"),
        pytest.param(lambda a, n: np.append(a, 0), "whole numbers", id="too_long"),
        pytest.param(lambda a, n: a + 0.5, "whole numbers", id="floats"),
    ],
)
def test_multi_discrete_action_out_of_range_is_refused(multi_discrete_env, change, message: str) -> None:
    space = multi_discrete_env.action_space
    with pytest.raises(InvalidArgumentError, match=message):
        multi_discrete_env.step(change(np.zeros(len(space.nvec), dtype=np.int64), space.nvec))


def test_multi_discrete_largest_choices_are_accepted(multi_discrete_env) -> None:
    multi_discrete_env.step(multi_discrete_env.action_space.nvec - 1)


# --- fault 14: frameskip ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "frameskip",
    [2**31, 2**32 + 4, 2**64, 0, -4, np.int64(2**40)],
    ids=["2**31", "2**32+4", "2**64", "zero", "negative", "int64_2**40"],
)
def test_frameskip_that_does_not_fit_is_refused(frameskip: int) -> None:
    with pytest.raises(InvalidArgumentError, match="frameskip from 1 to 2147483647"):
        retrokit.make(AIRSTRIKER, frameskip=frameskip)


@pytest.mark.parametrize("frameskip", [4, np.int64(4), np.int32(4), np.uint16(4)], ids=["int", "int64", "int32", "uint16"])
def test_frameskip_accepts_numpy_integers_and_runs_that_many_frames(frameskip) -> None:
    env = retrokit.make(DASHER, frameskip=frameskip)
    _, info = env.reset(seed=0)
    _, _, _, _, after = env.step(env.action_space.sample() * 0)
    assert after["frame"] - info["frame"] == 4  # Dasher counts its main-loop frames in RAM
    assert type(env.frameskip) is int
    env.close()


def test_native_run_refuses_frame_counts_past_a_c_int(airstriker) -> None:
    with pytest.raises(InvalidArgumentError, match="frames must be 0 or more and at most 2147483647"):
        airstriker.run(0, 2**32 + 4)


# --- fault 15: wrongly typed arguments, misspelled keywords, off-screen crops ------------------------

WRONG = [
    pytest.param((5,), {}, "game to be a game's name", id="game_int"),
    pytest.param((AIRSTRIKER, 5), {}, "state to be", id="state_int"),
    pytest.param((AIRSTRIKER, None, 5), {}, "scenario to be", id="scenario_int"),
    pytest.param((AIRSTRIKER,), {"frameskip": "4"}, "frameskip to be a whole number", id="frameskip_str"),
    pytest.param((AIRSTRIKER,), {"frameskip": 4.0}, "frameskip to be a whole number", id="frameskip_float"),
    pytest.param((AIRSTRIKER,), {"frameskip": True}, "frameskip to be a whole number", id="frameskip_bool"),
    pytest.param((AIRSTRIKER,), {"sticky_prob": "0.25"}, "sticky_prob to be a number", id="sticky_prob_str"),
    pytest.param((AIRSTRIKER,), {"sticky_prob": float("nan")}, r"sticky_prob in \[0, 1\]", id="sticky_prob_nan"),
    pytest.param((AIRSTRIKER,), {"sticky_prob": 1.5}, r"sticky_prob in \[0, 1\]", id="sticky_prob_above_1"),
    pytest.param((AIRSTRIKER,), {"players": "2"}, "players to be a whole number", id="players_str"),
    pytest.param((AIRSTRIKER,), {"max_episode_steps": "10"}, "max_episode_steps to be", id="max_episode_steps_str"),
    pytest.param((AIRSTRIKER,), {"max_episode_steps": 2**64}, "max_episode_steps from 1", id="max_episode_steps_huge"),
    pytest.param((AIRSTRIKER,), {"record": 5}, "record to be a folder path", id="record_int"),
    pytest.param((AIRSTRIKER,), {"options": 5}, "options to map", id="options_int"),
    pytest.param((AIRSTRIKER,), {"options": {"region": 1}}, "options to map", id="options_int_value"),
    pytest.param((AIRSTRIKER,), {"scenario_every_frame": "no"}, "True or False", id="scenario_every_frame_str"),
    pytest.param((AIRSTRIKER,), {"skip_video": 1}, "True or False", id="skip_video_int"),
    pytest.param((AIRSTRIKER,), {"obs_type": ["rgb"]}, "obs_type to be one of", id="obs_type_list"),
    pytest.param((AIRSTRIKER,), {"obs_type": "rbg"}, "Did you mean 'rgb'", id="obs_type_typo"),
    pytest.param((AIRSTRIKER,), {"action_type": "discreet"}, "Did you mean 'discrete'", id="action_type_typo"),
    pytest.param((AIRSTRIKER,), {"render_mode": "rgb_aray"}, "Did you mean 'rgb_array'", id="render_mode_typo"),
]


@pytest.mark.parametrize("args,kwargs,message", WRONG)
def test_wrongly_typed_argument_is_an_invalid_argument_error(args: tuple, kwargs: dict, message: str) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        retrokit.make(*args, **kwargs)


def test_a_game_object_is_taken_as_well_as_a_name() -> None:
    env = retrokit.make(find_game(DASHER), frameskip=2)
    assert env.game.name == DASHER
    env.close()


@pytest.mark.parametrize(
    "keyword,suggestion",
    [("framskip", "frameskip"), ("sticky_probability", "sticky_prob"), ("render", "render_mode"), ("max_steps", "max_episode_steps")],
    ids=["framskip", "sticky_probability", "render", "max_steps"],
)
def test_misspelled_keyword_gets_a_did_you_mean(keyword: str, suggestion: str) -> None:
    with pytest.raises(UnknownNameError, match=f"Did you mean '{suggestion}'"):
        retrokit.make(AIRSTRIKER, **{keyword: 4})


def test_the_sonic_preset_checks_keywords_before_looking_for_its_rom() -> None:
    with pytest.raises(UnknownNameError, match="Did you mean 'frameskip'"):
        gymnasium.make("retrokit/SonicTheHedgehog-GreenHillZone.Act1-v0", framskip=4)


def test_gymnasium_make_checks_keywords_too() -> None:
    with pytest.raises(UnknownNameError, match="Did you mean 'frameskip'"):
        gymnasium.make("retrokit/Airstriker-Genesis-v0", framskip=4)


def test_make_vec_checks_keywords_too() -> None:
    with pytest.raises(UnknownNameError, match="Did you mean 'frameskip'"):
        retrokit.make_vec(AIRSTRIKER, 2, framskip=4)


@pytest.mark.parametrize(
    "crop",
    [[400, 0, 10, 10], [0, 300, 10, 10], [320, 0, 0, 0], [0, 224, 0, 10]],
    ids=["right_of_the_screen", "below_the_screen", "at_the_right_edge_to_the_edge", "at_the_bottom_edge"],
)
def test_off_screen_crop_is_refused(crop: list[int]) -> None:
    with pytest.raises(InvalidArgumentError, match="crop .* to keep part of the 320x224 screen"):
        retrokit.make(AIRSTRIKER, scenario={"reward": "score", "crop": crop})


def test_crop_partly_on_screen_is_clipped() -> None:
    env = retrokit.make(AIRSTRIKER, scenario={"reward": "score", "crop": [300, 200, 100, 100]})
    assert env.observation_space.shape == (24, 20, 3)
    env.close()


def test_the_checked_options_are_exactly_retroenvs_keywords() -> None:
    keywords = [p.name for p in inspect.signature(RetroEnv).parameters.values() if p.kind is p.KEYWORD_ONLY]
    assert sorted(OPTIONS) == sorted(keywords)


# --- Gymnasium ids ---------------------------------------------------------------------------------------


def test_every_game_id_carries_a_version() -> None:
    ids = [env_id for env_id in gymnasium.registry if env_id.startswith("retrokit/")]
    assert "retrokit/Airstriker-Genesis-v0" in ids and "retrokit/Dasher-Genesis-v0" in ids
    assert all(gymnasium.registry[env_id].version == 0 for env_id in ids)


def test_versioned_id_makes_the_game() -> None:
    env = gymnasium.make("retrokit/Dasher-Genesis-v0", frameskip=np.int64(2))
    _, info = env.reset(seed=0)
    assert env.unwrapped.game.name == DASHER and "p1_x" in info
    env.close()


def test_every_sonic_level_is_registered_with_the_preset() -> None:
    ids = {f"retrokit/{game.removesuffix('-Genesis')}-{state}-v0": (game, state) for game, state in sonic.levels()}
    assert len(ids) == 58
    for env_id, (game, state) in ids.items():
        spec = gymnasium.spec(env_id)
        assert spec.entry_point == "retrokit.envs.sonic:make" and spec.kwargs == {"game": game, "state": state}


def test_sonic_level_id_reaches_the_preset() -> None:
    # No Sonic ROM on test machines: the preset's own message about importing it shows the id was resolved.
    with pytest.raises(RomNotFoundError, match="SonicTheHedgehog-Genesis"):
        gymnasium.make("retrokit/SonicTheHedgehog-GreenHillZone.Act1-v0")


@pytest.mark.parametrize(
    ("keyword", "value"),
    [("frameskip", 2**31), ("sticky_prob", float("nan")), ("obs_type", "rbg"), ("scenario_every_frame", "yes")],
    ids=["frameskip-too-big", "sticky-nan", "obs-type-typo", "flag-not-bool"],
)
def test_a_retroenv_made_directly_follows_makes_rules(keyword: str, value: object) -> None:
    from retrokit.envs.env import RetroEnv

    with pytest.raises(InvalidArgumentError, match=keyword):
        RetroEnv(AIRSTRIKER, **{keyword: value})


def test_a_retroenv_made_directly_takes_numpy_integers() -> None:
    from retrokit.envs.env import RetroEnv

    env = RetroEnv(AIRSTRIKER, frameskip=np.int64(4))
    assert env.frameskip == 4 and type(env.frameskip) is int
    env.close()


@pytest.mark.parametrize(
    ("keywords", "expected"),
    [
        pytest.param({"use_restricted_actions": 2}, "use action_type='filtered', 'all', 'discrete'", id="use_restricted_actions"),
        pytest.param({"inttype": 1}, "stable-retro's 'inttype'; leave it out", id="inttype"),
        pytest.param({"info": "data"}, "game.yaml or data.json", id="info"),
    ],
)
def test_stable_retro_keywords_name_retrokits_equivalent(keywords: dict, expected: str) -> None:
    with pytest.raises(UnknownNameError, match=re.escape(expected)):
        retrokit.make("Airstriker-Genesis", **keywords)


def test_stable_retro_enums_name_the_string_to_pass() -> None:
    class Actions(enum.Enum):  # stable-retro's enums, as its package defines them
        DISCRETE = 2

    class Observations(enum.Enum):
        IMAGE = 0

    with pytest.raises(InvalidArgumentError, match=re.escape("pass action_type='discrete' for Actions.DISCRETE")):
        retrokit.make("Airstriker-Genesis", action_type=Actions.DISCRETE)
    with pytest.raises(InvalidArgumentError, match=re.escape("pass obs_type='rgb' for Observations.IMAGE")):
        retrokit.make("Airstriker-Genesis", obs_type=Observations.IMAGE)
