"""The Gymnasium env on the real core: conformance, options, seeding, errors."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import retrokit
from retrokit.envs.env import RetroEnv, State
from retrokit.errors import (
    GameNotFoundError,
    InvalidArgumentError,
    RomNotFoundError,
    StateNotFoundError,
)

AIRSTRIKER = "Airstriker-Genesis"
OBS_TYPES = ["rgb", "ram"]
ACTION_TYPES = ["all", "filtered", "discrete", "multi_discrete"]


def fire_and_wander(env: RetroEnv, step: int) -> object:
    """An action that makes Airstriker shoot, move and score, in any action type."""
    names = (["B"] if step % 8 < 4 else []) + [["UP"], ["DOWN"], ["LEFT"], ["RIGHT"]][(step // 16) % 4]
    mask = env.emulator.system.mask(names)
    kind = env.actions.action_type
    if kind in ("all", "filtered"):
        return env.actions.press(names)
    picks = [combos.index(mask & gmask) if (mask & gmask) in combos else 0 for combos, gmask in zip(env.actions.combos, env.actions.group_masks)]
    if kind == "multi_discrete":
        return np.array(picks)
    index, scale = 0, 1
    for pick, combos in zip(picks, env.actions.combos):
        index += pick * scale
        scale *= len(combos)
    return index


@pytest.mark.parametrize("action_type", ACTION_TYPES)
@pytest.mark.parametrize("obs_type", OBS_TYPES)
@pytest.mark.parametrize("game", [AIRSTRIKER, "Dasher-Genesis"])
def test_check_env_passes(game: str, obs_type: str, action_type: str) -> None:
    env = retrokit.make(game, obs_type=obs_type, action_type=action_type, frameskip=4, sticky_prob=0.25)
    check_env(env, skip_render_check=True)
    env.close()


@pytest.mark.parametrize("action_type", ACTION_TYPES)
def test_each_action_type_drives_the_game(action_type: str) -> None:
    env = retrokit.make(AIRSTRIKER, action_type=action_type, frameskip=4)
    env.reset(seed=0)
    total = 0.0
    for step in range(300):
        _, reward, terminated, _truncated, info = env.step(fire_and_wander(env, step))
        total += reward
        if terminated:
            break
    assert total > 0 and total == info["score"]  # Airstriker's scenario rewards the score's change
    env.close()


def test_action_space_sizes_follow_the_genesis_groups() -> None:
    sizes = {}
    for action_type in ACTION_TYPES:
        env = retrokit.make(AIRSTRIKER, action_type=action_type)
        sizes[action_type] = env.action_space
        env.close()
    assert sizes["all"] == gymnasium.spaces.MultiBinary(12)
    assert sizes["discrete"] == gymnasium.spaces.Discrete(3 * 3 * 14)
    assert list(sizes["multi_discrete"].nvec) == [3, 3, 14]


def test_press_names_buttons_in_gym_retros_order() -> None:
    env = retrokit.make(AIRSTRIKER, action_type="all")
    assert env.actions.press(["B", "RIGHT", "Z"]).tolist() == [1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1]
    env.close()
    env = retrokit.make(AIRSTRIKER, action_type="discrete")  # the index of the combination, as JERK presses it
    assert env.get_action_meaning(env.actions.press(["B"])) == ["B"]
    with pytest.raises(InvalidArgumentError, match="one listed combination of each group"):
        env.actions.press(["UP", "DOWN"])
    env.close()


def test_filtered_actions_drop_what_gym_retro_drops() -> None:
    env = retrokit.make(AIRSTRIKER, action_type="filtered")
    system = env.emulator.system
    f = lambda names: system.buttons_of(env.actions.filter(system.mask(names)))
    assert f(["UP", "DOWN", "LEFT"]) == ["LEFT"]  # opposite directions are no combination
    assert f(["A", "B"]) == ["B", "A"]
    assert f(["A", "C"]) == []
    assert f(["START", "RIGHT"]) == ["RIGHT"]
    env.close()


def test_info_holds_every_ram_field_by_name() -> None:
    env = retrokit.make(AIRSTRIKER)
    _, info = env.reset(seed=0)
    assert set(info) == {"score", "lives", "gameover"}
    assert info["lives"] == 3
    env.close()


def test_frameskip_runs_that_many_frames_per_step() -> None:
    env = retrokit.make(AIRSTRIKER, frameskip=4)
    env.reset(seed=0)
    before = env.emulator.frame
    env.step(env.action_space.sample() * 0)
    assert env.emulator.frame - before == 4
    env.close()


def test_step_limit_truncates_not_terminates() -> None:
    env = retrokit.make(AIRSTRIKER, max_episode_steps=5)
    env.reset(seed=0)
    flags = [env.step(env.action_space.sample() * 0)[2:4] for _ in range(5)]
    assert flags[:4] == [(False, False)] * 4 and flags[4] == (False, True)
    env.close()


def rollout(env: RetroEnv, seed: int, steps: int = 200) -> tuple[list[float], bytes, list[dict]]:
    obs, _ = env.reset(seed=seed)
    rewards, infos = [], []
    for step in range(steps):
        obs, reward, terminated, truncated, info = env.step(fire_and_wander(env, step))
        rewards.append(reward)
        infos.append(info)
        if terminated or truncated:
            break
    return rewards, obs.tobytes(), infos


def test_same_seed_same_actions_same_trajectory() -> None:
    env = retrokit.make(AIRSTRIKER, frameskip=4, sticky_prob=0.5)
    first = rollout(env, seed=3)
    second = rollout(env, seed=3)
    other = rollout(env, seed=4)
    assert first == second
    assert other != first  # the sticky draws follow the seed
    env.close()


def test_every_frame_scenario_sums_the_frames_rewards() -> None:
    per_step = retrokit.make(AIRSTRIKER, frameskip=4)
    per_frame = retrokit.make(AIRSTRIKER, frameskip=4, scenario_every_frame=True)
    a, b = rollout(per_step, seed=0, steps=300), rollout(per_frame, seed=0, steps=300)
    # Airstriker's reward is the score's change: summing it per frame or per step agrees.
    assert sum(a[0]) == sum(b[0]) > 0
    assert a[2][-1] == b[2][-1]
    per_step.close()
    per_frame.close()


def test_gymnasium_make_finds_registered_games() -> None:
    env = gymnasium.make("retrokit/Airstriker-Genesis-v0", frameskip=4, max_episode_steps=3)
    env.reset(seed=0)
    for _ in range(3):
        *_, truncated, _ = env.step(env.action_space.sample())
    assert truncated
    env.close()


def test_render_rgb_array_returns_the_screen() -> None:
    env = retrokit.make(AIRSTRIKER, render_mode="rgb_array")
    obs, _ = env.reset(seed=0)
    frame = env.render()
    assert frame.shape == (224, 320, 3) and (frame == obs).all()
    env.close()


def test_power_on_state_boots_the_rom() -> None:
    env = retrokit.make(AIRSTRIKER, state=State.NONE)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (224, 320, 3)
    env.close()


@pytest.mark.parametrize(
    "kwargs,error,message",
    [
        ({"game": "Airstriker-Genesys"}, GameNotFoundError, "Did you mean 'Airstriker-Genesis'"),
        ({"game": AIRSTRIKER, "state": "Level2"}, StateNotFoundError, "Did you mean 'Level1'"),
        ({"game": AIRSTRIKER, "obs_type": "rbg"}, InvalidArgumentError, "Did you mean 'rgb'"),
        ({"game": AIRSTRIKER, "action_type": "discreet"}, InvalidArgumentError, "Did you mean 'discrete'"),
        ({"game": AIRSTRIKER, "frameskip": 0}, InvalidArgumentError, "frameskip"),
        ({"game": AIRSTRIKER, "sticky_prob": 2.0}, InvalidArgumentError, r"sticky_prob in \[0, 1\]"),
        ({"game": AIRSTRIKER, "players": 2}, InvalidArgumentError, "1 to 1 players"),
    ],
    ids=["unknown-game", "unknown-state", "obs-type", "action-type", "frameskip", "sticky", "players"],
)
def test_bad_options_say_what_was_expected(kwargs: dict, error: type, message: str) -> None:
    with pytest.raises(error, match=message):
        retrokit.make(**kwargs)


def test_missing_rom_says_how_to_import(monkeypatch: pytest.MonkeyPatch, tmp_path) -> None:
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path))
    with pytest.raises(RomNotFoundError, match="retrokit import"):
        retrokit.make("SonicTheHedgehog-Genesis", "GreenHillZone.Act1", "contest")


@pytest.mark.parametrize("every_frame", [False, True], ids=["per-step", "per-frame"])
def test_recorded_movies_replay_what_the_agent_saw(tmp_path, every_frame: bool) -> None:
    from retrokit.movie import play, read_bk2

    env = retrokit.make(
        "Dasher-Genesis", frameskip=4, sticky_prob=0.5, max_episode_steps=40, record=tmp_path,
        action_type="all", scenario_every_frame=every_frame,
    )
    seen, ends = [], []  # each step's observation, and its last frame's index in its movie
    for episode in range(2):
        env.reset(seed=episode)
        frames = 0
        for step in range(40):
            names = ["RIGHT"] + (["B"] if step % 5 < 2 else []) if step % 7 else ["LEFT"]
            before = env.emulator.frame
            obs, _, terminated, truncated, _ = env.step(env.actions.press(names))
            frames += env.emulator.frame - before  # fewer than 4 when the scenario ends a step early
            seen.append(obs.copy())
            ends.append((episode, frames - 1))
            if terminated or truncated:
                break
    env.close()
    movies = sorted(tmp_path.glob("*.bk2"))
    assert [m.name for m in movies] == [f"Dasher-Genesis-Zone1.Act1-{i:06d}.bk2" for i in range(2)]
    replays = [list(play(movie)) for movie in movies]
    frames = [replays[episode][index] for episode, index in ends]
    lengths = {episode: index + 1 for episode, index in ends}  # each episode's last step wins
    assert [len(r) for r in replays] == [lengths[0], lengths[1]]
    assert all((a == b).all() for a, b in zip(frames, seen))
    # With p=0.5 some steps' first frames kept the previous buttons, and the movie says so.
    inputs = read_bk2(movies[0]).frames
    assert any(inputs[i] != inputs[i + 1] for i in range(0, len(inputs) - 4, 4))


def test_human_rendering_draws_into_a_window(monkeypatch: pytest.MonkeyPatch) -> None:
    pygame = pytest.importorskip("pygame")
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")  # a real SDL window, with no screen needed
    env = retrokit.make("Dasher-Genesis", render_mode="human", frameskip=4)
    obs, _ = env.reset(seed=0)
    for _ in range(3):
        obs, *_ = env.step(env.actions.press(["RIGHT"]))
    surface = pygame.display.get_surface()
    assert surface.get_size() == (640, 448)  # the frame, scaled twice
    shown = pygame.surfarray.array3d(surface).swapaxes(0, 1)[::2, ::2]
    assert (shown == obs).all()
    env.close()


@pytest.mark.parametrize(
    ("crop", "shape"),
    [
        ([8, 16, 100, 50], (50, 100, 3)),
        ([8, 16, 0, 0], (224 - 16, 320 - 8, 3)),  # 0 reaches the screen's edge, as in Gym Retro
        ([300, 200, 100, 100], (24, 20, 3)),  # clipped at the edge
    ],
    ids=["inside", "zero-to-the-edge", "clipped"],
)
def test_scenario_crop_shapes_the_observation(crop: list[int], shape: tuple[int, int, int]) -> None:
    env = retrokit.make(AIRSTRIKER, scenario={"reward": "score", "crop": crop}, render_mode="rgb_array")
    x, y = crop[0], crop[1]
    obs, _ = env.reset(seed=0)
    for _ in range(30):
        assert obs.shape == shape == env.observation_space.shape
        assert (obs == env.render()[y : y + shape[0], x : x + shape[1]]).all()
        obs = env.step(env.action_space.sample())[0]
    env.close()
