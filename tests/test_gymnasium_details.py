"""What Gymnasium's tools read from an env: its frame rate, its render modes, its action checks, its seeds (Dasher)."""

from __future__ import annotations

import subprocess
import sys

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import retrokit
from retrokit.envs import multiplayer
from retrokit.errors import InvalidArgumentError, MissingExtraError
from retrokit.host.systems import get_system

GAME = "Dasher-Genesis"
NTSC, PAL = 59.922743, 49.701459
PAL_OPTIONS = {"genesis_plus_gx_region_detect": "pal"}


def without_pygame(code: str) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh interpreter where ``import pygame`` fails, as on a machine without it."""
    blocked = "import sys; sys.modules['pygame'] = None\n"
    return subprocess.run([sys.executable, "-c", blocked + code], capture_output=True, text=True, timeout=120, check=False)


# --- render_fps ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "frameskip,options,rate", [(1, None, NTSC), (4, None, NTSC), (4, PAL_OPTIONS, PAL)], ids=["ntsc", "ntsc-skip4", "pal-skip4"]
)
def test_render_fps_is_the_consoles_rate_over_the_frame_skip(frameskip: int, options, rate: float) -> None:
    env = retrokit.make(GAME, frameskip=frameskip, options=options, obs_type="ram")
    assert env.metadata["render_fps"] == pytest.approx(rate / frameskip)
    assert env.emulator.av_info()["fps"] == pytest.approx(rate, abs=1e-4)  # the core runs at the descriptor's rate
    env.close()


def test_render_fps_is_per_env_and_reaches_gymnasium_make_and_the_pettingzoo_env() -> None:
    four = gymnasium.make(f"retrokit/{GAME}-v0", frameskip=4, obs_type="ram")
    two = gymnasium.make(f"retrokit/{GAME}-v0", frameskip=2, obs_type="ram")
    assert four.metadata["render_fps"] == pytest.approx(NTSC / 4) and two.metadata["render_fps"] == pytest.approx(NTSC / 2)
    assert retrokit.RetroEnv.metadata["render_fps"] == 60  # the class's own is left alone
    players = multiplayer.parallel_env(GAME, frameskip=3, obs_type="ram")
    assert players.metadata["render_fps"] == pytest.approx(NTSC / 3) and players.metadata["name"] == f"{GAME}_v0"
    for env in (four, two, players):
        env.close()


def test_the_descriptors_give_the_real_rates() -> None:
    assert get_system("GameBoy").frame_rate() == pytest.approx(59.7275)
    assert get_system("Genesis").frame_rate(50.0) == pytest.approx(PAL)  # the core's report picks the standard
    assert get_system("Genesis").frame_rate(60.0) == pytest.approx(NTSC)
    assert get_system("FBNeo").frame_rate(57.5) == 57.5  # an arcade board's rate is the game's: the core's


# --- render modes and pygame --------------------------------------------------------------------


def test_check_env_passes_with_pygame_and_lists_human() -> None:
    pytest.importorskip("pygame", reason="pygame is not installed")
    env = gymnasium.make(f"retrokit/{GAME}-v0")
    assert env.unwrapped.metadata["render_modes"] == ["rgb_array", "human"]
    check_env(env.unwrapped)
    env.close()


def test_check_env_passes_without_pygame_and_human_is_not_listed() -> None:
    result = without_pygame(
        "import gymnasium, retrokit\n"
        "from gymnasium.utils.env_checker import check_env\n"
        f"env = gymnasium.make('retrokit/{GAME}-v0')\n"
        "check_env(env.unwrapped)\n"
        "print(env.unwrapped.metadata['render_modes'], retrokit.multiplayer.RetroParallelEnv.metadata['render_modes'])\n"
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "['rgb_array'] ['rgb_array']"


def test_human_without_pygame_fails_at_make_saying_how_to_install() -> None:
    result = without_pygame(
        "import gymnasium, retrokit\n"
        "from retrokit.errors import MissingExtraError\n"
        f"for make in (lambda: retrokit.make('{GAME}', render_mode='human'),\n"
        f"             lambda: gymnasium.make('retrokit/{GAME}-v0', render_mode='human'),\n"
        f"             lambda: retrokit.multiplayer.parallel_env('{GAME}', render_mode='human')):\n"
        "    try:\n"
        "        make()\n"
        "    except MissingExtraError as error:\n"
        "        print(error)\n"
    )
    assert result.returncode == 0, result.stderr
    lines = result.stdout.strip().splitlines()
    assert len(lines) == 3 and all("pip install 'retrokit-rl[human]'" in line for line in lines), result.stdout


def test_human_without_pygame_is_refused_in_process(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "pygame", None)
    with pytest.raises(MissingExtraError, match="retrokit-rl\\[human\\]"):
        retrokit.make(GAME, render_mode="human")
    env = retrokit.make(GAME, obs_type="ram")
    assert env.metadata["render_modes"] == ["rgb_array"]
    env.close()


# --- actions outside the MultiBinary space ------------------------------------------------------

NOT_BINARY = [
    np.array([2] + [0] * 11, dtype=np.int8),
    np.array([0] * 11 + [-1], dtype=np.int64),
    np.array([0.5] + [0] * 11),
    [0, 0, 2] + [0] * 9,
]
NOT_BINARY_IDS = ["2-int8", "minus1-int64", "half-float", "2-list"]


@pytest.mark.parametrize("action_type", ["all", "filtered"])
@pytest.mark.parametrize("action", NOT_BINARY, ids=NOT_BINARY_IDS)
def test_a_retro_env_refuses_a_multibinary_action_that_is_not_0_or_1(action, action_type: str) -> None:
    env = retrokit.make(GAME, action_type=action_type, obs_type="ram")
    env.reset(seed=0)
    with pytest.raises(InvalidArgumentError, match="0s and 1s"):
        env.step(action)
    env.step(np.ones(12, dtype=np.int8))  # a good action still plays
    env.close()


@pytest.mark.parametrize("action", NOT_BINARY[:3], ids=NOT_BINARY_IDS[:3])
def test_the_vector_env_and_pettingzoo_refuse_it_too(action) -> None:
    vec = retrokit.make_vec(GAME, 2, obs_type="ram")
    vec.reset(seed=0)
    with pytest.raises(InvalidArgumentError, match="0s and 1s"):
        vec.step(np.stack([np.zeros(12, dtype=action.dtype), action]))
    vec.close()
    players = multiplayer.parallel_env(GAME, obs_type="ram")
    players.reset(seed=0)
    with pytest.raises(InvalidArgumentError, match="0s and 1s"):
        players.step({"player_1": np.zeros(12, dtype=np.int8), "player_2": action})
    players.close()


# --- seeds --------------------------------------------------------------------------------------

GOOD_SEEDS = [np.int64(5), np.uint32(5), np.int8(5), 5, 2**70]
BAD_SEEDS = [np.int64(-5), -5, 1.5, np.float64(2.0), "5", True, np.bool_(False), [5]]


@pytest.mark.parametrize("seed", GOOD_SEEDS, ids=lambda s: f"{type(s).__name__}-{s}")
def test_numpy_and_python_integers_seed_every_env(seed) -> None:
    env = retrokit.make(GAME, obs_type="ram", sticky_prob=0.5)
    env.reset(seed=seed)
    first = [env.step(np.ones(12, dtype=np.int8))[0].tobytes() for _ in range(3)]
    env.reset(seed=int(seed))
    assert [env.step(np.ones(12, dtype=np.int8))[0].tobytes() for _ in range(3)] == first
    env.close()
    players = multiplayer.parallel_env(GAME, obs_type="ram")
    players.reset(seed=seed)
    players.close()


@pytest.mark.parametrize("seed", BAD_SEEDS, ids=lambda s: f"{type(s).__name__}-{s}")
def test_a_negative_or_non_integer_seed_is_refused_everywhere(seed) -> None:
    env = retrokit.make(GAME, obs_type="ram")
    vec = retrokit.make_vec(GAME, 1, obs_type="ram")
    players = multiplayer.parallel_env(GAME, obs_type="ram")
    aec = multiplayer.env(GAME, obs_type="ram")
    try:
        for reset in (env.reset, players.reset, aec.reset):
            with pytest.raises(InvalidArgumentError, match="seed"):
                reset(seed=seed)
        if not isinstance(seed, list):  # [5] is one seed per env for a vector env of 1
            with pytest.raises(InvalidArgumentError, match="seed"):
                vec.reset(seed=seed)
        with pytest.raises(InvalidArgumentError, match="seed"):
            vec.reset(seed=[seed])
    finally:
        for each in (env, vec, players, aec):
            each.close()


def test_a_vector_env_takes_numpy_seeds_one_per_env_or_one_for_all() -> None:
    vec = retrokit.make_vec(GAME, 2, obs_type="ram")
    a, _ = vec.reset(seed=np.int64(7))
    b, _ = vec.reset(seed=np.array([7, 8]))
    assert np.array_equal(a, b)
    with pytest.raises(InvalidArgumentError, match="Expected 2 seeds"):
        vec.reset(seed=[1, 2, 3])
    vec.close()
