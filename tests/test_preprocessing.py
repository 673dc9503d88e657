"""Native observation preprocessing gives what Gymnasium's wrappers give, defined the same way.

Each reference is a frame-by-frame env (frameskip 1) wrapped in Gymnasium's own
wrappers (GrayscaleObservation, ResizeObservation, which resizes with OpenCV's
INTER_AREA, FrameStackObservation) and a MaxAndSkip like Atari's; the env under
test makes the same observation natively with frameskip 4. They must agree to
within 1 per pixel (resizing rounds floats in another order than OpenCV's).
"""

from __future__ import annotations

import cv2
import gymnasium
import numpy as np
import pytest
from gymnasium.wrappers import FrameStackObservation, GrayscaleObservation, ResizeObservation, TransformObservation

import retrokit
from retrokit.envs import env as env_module
from retrokit.envs import sonic
from retrokit.errors import InvalidArgumentError, RetrokitError, UnknownNameError
from retrokit.host.cores import built_core

SKIP = 4
AIRSTRIKER, DASHER = "Airstriker-Genesis", "Dasher-Genesis"
INTERPOLATIONS = {"area": cv2.INTER_AREA, "bilinear": cv2.INTER_LINEAR, "nearest": cv2.INTER_NEAREST}


class MaxAndSkip(gymnasium.Wrapper):
    """Atari's frame skip: repeat the action ``skip`` frames; with ``pool``, the max of the last two."""

    def __init__(self, env: gymnasium.Env, skip: int, pool: bool) -> None:
        super().__init__(env)
        self.skip, self.pool = skip, pool

    def step(self, action):
        frames, total = [], 0.0
        for _ in range(self.skip):
            obs, reward, terminated, truncated, info = self.env.step(action)
            frames.append(obs)
            total += reward
            if terminated or truncated:
                break
        obs = np.maximum(frames[-2], frames[-1]) if self.pool and len(frames) > 1 else frames[-1]
        return obs, total, terminated, truncated, info


def cropped(env: gymnasium.Env, crop: tuple[int, int, int, int]) -> gymnasium.Env:
    top, bottom, left, right = crop
    height, width = env.observation_space.shape[:2]
    shape = (height - top - bottom, width - left - right, 3)
    return TransformObservation(
        env, lambda o: o[top : height - bottom, left : width - right], gymnasium.spaces.Box(0, 255, shape, np.uint8)
    )


def resized(env: gymnasium.Env, size: tuple[int, int], method: str) -> gymnasium.Env:
    if method == "area":
        return ResizeObservation(env, size)  # Gymnasium's own: cv2.INTER_AREA
    channels = env.observation_space.shape[2:]
    space = gymnasium.spaces.Box(0, 255, (*size, *channels), np.uint8)
    interpolation = INTERPOLATIONS[method]
    return TransformObservation(
        env, lambda o: cv2.resize(o, size[::-1], interpolation=interpolation).reshape(space.shape), space
    )


def reference(game: str, crop=None, grayscale=False, max_pool=False, resize=None, method="area", frame_stack=1):
    """Gymnasium's wrappers, in native preprocessing's order, around a frame-by-frame env."""
    env: gymnasium.Env = retrokit.make(game, frameskip=1, sticky_prob=0.0)
    if crop is not None:
        env = cropped(env, crop)
    if grayscale:
        env = GrayscaleObservation(env, keep_dim=True)
    env = MaxAndSkip(env, SKIP, max_pool)
    if resize is not None:
        env = resized(env, resize, method)
    return FrameStackObservation(env, frame_stack)  # (N, H, W, C)


def as_native(stacked: np.ndarray, channels_first: bool) -> np.ndarray:
    """FrameStackObservation's (N, H, W, C) as native preprocessing lays it out: (H, W, N*C) or (N*C, H, W)."""
    n, h, w, c = stacked.shape
    if channels_first:
        return stacked.transpose(0, 3, 1, 2).reshape(n * c, h, w)
    return stacked.transpose(1, 2, 0, 3).reshape(h, w, n * c)


CONFIGS = {
    "airstriker-gray84-stack4-maxpool-channels-first": (
        AIRSTRIKER, {"grayscale": True, "resize": (84, 84), "frame_stack": 4, "max_pool": True, "channels_first": True}
    ),
    "dasher-crop-gray84-stack4-maxpool": (
        DASHER, {"crop": (8, 16, 16, 0), "grayscale": True, "resize": (84, 84), "frame_stack": 4, "max_pool": True}
    ),
    "airstriker-rgb-bilinear-stack2": (AIRSTRIKER, {"resize": (112, 80), "resize_method": "bilinear", "frame_stack": 2}),
    "dasher-rgb-nearest-crop": (DASHER, {"crop": (0, 24, 32, 32), "resize": (100, 130), "resize_method": "nearest"}),
    "dasher-gray-upscale-area-maxpool": (DASHER, {"grayscale": True, "resize": (300, 400), "max_pool": True}),
}


# Steps compared per configuration: enough for the stack to fill and the game to move for seconds.
STEPS = 48


@pytest.mark.parametrize("config", CONFIGS, ids=list(CONFIGS))
def test_native_preprocessing_equals_gymnasiums_wrappers(config: str) -> None:
    game, options = CONFIGS[config]
    native = retrokit.make(game, frameskip=SKIP, sticky_prob=0.0, **options)
    ref = reference(
        game, crop=options.get("crop"), grayscale=options.get("grayscale", False),
        max_pool=options.get("max_pool", False), resize=options.get("resize"),
        method=options.get("resize_method", "area"), frame_stack=options.get("frame_stack", 1),
    )  # fmt: skip
    first = options.get("channels_first", False)
    assert native.observation_space.shape == as_native(ref.observation_space.sample(), first).shape
    obs, _ = native.reset(seed=3)
    expected, _ = ref.reset(seed=3)
    space = native.action_space
    space.seed(3)
    start, moved = obs.copy(), 0
    for step in range(STEPS):
        assert native.observation_space.contains(obs)
        moved += not np.array_equal(obs, start)
        diff = np.abs(obs.astype(int) - as_native(expected, first).astype(int))
        assert diff.max() <= 1, f"{config}: step {step} differs by {diff.max()} at {np.argwhere(diff > 1)[:4]}"
        action = space.sample()
        obs, _, terminated, truncated, _ = native.step(action)
        # The reference asks the scenario every frame, the env once a step: rewards fall apart, and episodes
        # may end apart, while the frames, the same emulation, do not.
        expected, _, ref_terminated, ref_truncated, _ = ref.step(action)
        if terminated or truncated or ref_terminated or ref_truncated:
            break
    # Compared over frames that changed, not a still screen (the scenario may end an episode early).
    assert moved >= STEPS // 2, f"{config}: the observation changed on only {moved} of {step + 1} steps"
    native.close()
    ref.close()


class FrameButtons:
    """A stepper observer: player 1's buttons on every frame the env ran, sticky draws included."""

    def __init__(self) -> None:
        self.masks: list[int] = []

    def frames(self, first: tuple[int, ...], applied: tuple[int, ...], count: int) -> None:
        self.masks += [first[0]] + [applied[0]] * (count - 1)


class PooledFrames(gymnasium.Wrapper):
    """MaxAndSkip's pool over given frames: a step is a list of per-frame button arrays, run until the scenario
    ends the episode; the observation is the max of the last two frames run."""

    def step(self, frames):
        seen, total = [], 0.0
        for buttons in frames:
            obs, reward, terminated, truncated, info = self.env.step(buttons)
            seen.append(obs)
            total += reward
            if terminated or truncated:
                break
        obs = np.maximum(seen[-2], seen[-1]) if len(seen) > 1 else seen[-1]
        return obs, total, terminated, truncated, {**info, "frames": len(seen)}


# Ends the episode on the frame player 1 gets 8 pixels right of the start, which is most often not a step's last;
# short episodes reach every path below (two resets, two ends inside a step) in ~60 steps rather than ~380.
REACH = {"reward": "p1_x", "done": "p1_x > initial(p1_x) + 8"}


def test_max_pool_with_the_sonic_presets_rules_equals_gymnasiums_wrappers_over_frames_run_one_by_one() -> None:
    """The preset's rules (sticky frame skip 4, scenario every frame) and the RL preprocessing, on Dasher.

    The reference runs the very frames the env ran (its sticky draws included), one env step each, in
    Gymnasium's wrappers; where the scenario ends an episode inside a step, both end there, and the
    observation is the max of the frame that ended it and the one before.
    """
    options = {"grayscale": True, "resize": (84, 84), "frame_stack": 4, "max_pool": True}
    native = sonic.Discretizer(
        retrokit.make(DASHER, "Zone1.Act1", REACH, **sonic.RULES, **options, action_type="all"), sonic.ACTIONS
    )
    frame_env = retrokit.make(DASHER, "Zone1.Act1", REACH, frameskip=1, sticky_prob=0.0, action_type="all")
    ref = FrameStackObservation(ResizeObservation(PooledFrames(GrayscaleObservation(frame_env, keep_dim=True)), (84, 84)), 4)
    buttons = FrameButtons()
    base = native.unwrapped
    base.stepper.observers.append(buttons)
    width = base.actions.num_buttons
    obs, _ = native.reset(seed=2)
    expected, _ = ref.reset(seed=2)
    native.action_space.seed(2)
    ends_inside_a_step = episodes = 0
    for step in range(700):
        diff = np.abs(obs.astype(int) - as_native(expected, False).astype(int))
        assert diff.max() <= 1, f"step {step} differs by {diff.max()} at {np.argwhere(diff > 1)[:4]}"
        if episodes >= 2 and ends_inside_a_step >= 1:
            break  # every path compared: full steps, an end inside a step, the resets (by step 56 with these seeds)
        buttons.masks.clear()
        obs, reward, terminated, _truncated, _ = native.step(native.action_space.sample())
        frames = [((mask >> np.arange(width)) & 1).astype(np.int8) for mask in buttons.masks]
        expected, ref_reward, ref_terminated, _ref_truncated, info = ref.step(frames)
        assert (reward, terminated, info["frames"]) == (ref_reward, ref_terminated, len(frames))
        if terminated:
            episodes += 1
            ends_inside_a_step += len(frames) < sonic.FRAMESKIP
            obs, _ = native.reset()
            expected, _ = ref.reset()
    assert episodes >= 2 and ends_inside_a_step >= 1, (episodes, ends_inside_a_step)
    native.close()
    ref.close()


@pytest.mark.parametrize("every_frame", [False, True], ids=["scenario-once-a-step", "scenario-every-frame"])
def test_a_vector_env_gets_the_same_preprocessed_observations_as_single_envs(every_frame: bool) -> None:
    """Through autoresets too (max_episode_steps ends episodes): each episode's stack starts anew."""
    options = {"frameskip": SKIP, "sticky_prob": 0.25, "grayscale": True, "resize": (84, 84), "frame_stack": 4,
               "max_pool": True, "noop_max": 5, "max_episode_steps": 20, "scenario_every_frame": every_frame}  # fmt: skip
    vec = retrokit.make_vec(DASHER, 2, **options)
    singles = [retrokit.make(DASHER, **options) for _ in range(2)]
    assert vec.single_observation_space == singles[0].observation_space
    obs, _ = vec.reset(seed=5)
    for i, env in enumerate(singles):
        assert (obs[i] == env.reset(seed=5 + i)[0]).all()
    vec.action_space.seed(5)
    ended, resets = [False, False], 0
    for _ in range(50):
        actions = vec.action_space.sample()
        obs, rewards, terminated, truncated, _ = vec.step(actions)
        for i, env in enumerate(singles):
            if ended[i]:  # the vector's next-step autoreset
                expected, reward, done = env.reset()[0], 0.0, False
                resets += 1
            else:
                expected, reward, *flags, _ = env.step(actions[i])
                done = any(flags)
            assert (obs[i] == expected).all() and rewards[i] == reward
            assert bool(terminated[i] or truncated[i]) == done
            ended[i] = done
    assert resets >= 2
    vec.close()
    for env in singles:
        env.close()


SPACES = {
    "gray": ({"grayscale": True}, (224, 320, 1)),
    "gray-channels-first": ({"grayscale": True, "channels_first": True}, (1, 224, 320)),
    "rgb-stack3": ({"frame_stack": 3}, (224, 320, 9)),
    "rgb-stack3-channels-first": ({"frame_stack": 3, "channels_first": True}, (9, 224, 320)),
    "crop": ({"crop": (10, 20, 30, 40)}, (194, 250, 3)),
    "gray84-stack4": ({"grayscale": True, "resize": (84, 84), "frame_stack": 4}, (84, 84, 4)),
    "crop-resize-channels-first": ({"crop": (0, 0, 0, 1), "resize": (50, 60), "channels_first": True}, (3, 50, 60)),
}


@pytest.mark.parametrize("name", SPACES, ids=list(SPACES))
def test_observation_spaces_are_exact(name: str) -> None:
    options, shape = SPACES[name]
    env = retrokit.make(AIRSTRIKER, frameskip=SKIP, **options)
    assert env.observation_space == gymnasium.spaces.Box(0, 255, shape, np.uint8)
    obs, _ = env.reset(seed=0)
    assert obs.shape == shape and obs.dtype == np.uint8
    assert env.step(env.action_space.sample())[0].shape == shape
    env.close()


HOSTILE = {
    "grayscale-not-a-bool": {"grayscale": "yes"},
    "resize-zero": {"resize": (0, 84)},
    "resize-negative": {"resize": (-84, 84)},
    "resize-one-number": {"resize": (84,)},
    "resize-a-string": {"resize": "84x84"},
    "resize-a-float": {"resize": (84.5, 84)},
    "resize-huge": {"resize": (10**6, 84)},
    "resize-method-misspelled": {"resize": (84, 84), "resize_method": "aera"},
    "resize-method-not-a-string": {"resize_method": 2},
    "crop-larger-than-the-screen": {"crop": (200, 30, 0, 0)},
    "crop-wider-than-the-screen": {"crop": (0, 0, 320, 0)},
    "crop-negative": {"crop": (-1, 0, 0, 0)},
    "crop-three-numbers": {"crop": (1, 2, 3)},
    "frame-stack-zero": {"frame_stack": 0},
    "frame-stack-huge": {"frame_stack": 10**6},
    "frame-stack-float": {"frame_stack": 4.0},
    "observation-too-large": {"resize": (4096, 4096), "frame_stack": 64},
    "channels-first-none": {"channels_first": None},
    "preprocessing-ram": {"grayscale": True, "obs_type": "ram"},
    "noop-max-negative": {"noop_max": -1},
    "noop-max-huge": {"noop_max": 10**9},
    "reward-clip-negative": {"reward_clip": -1},
    "reward-clip-nan": {"reward_clip": float("nan")},
    "reward-clip-string": {"reward_clip": "sign"},
    "info-keys-a-string": {"info_keys": "score"},
    "info-keys-not-strings": {"info_keys": [1, 2]},
    "info-keys-unknown-field": {"info_keys": ["scroe"]},
    "state-weights-empty": {"state": {}},
    "state-weights-negative": {"state": {"Level1": -1}},
    "state-weights-all-zero": {"state": {"Level1": 0}},
    "state-weights-not-numbers": {"state": {"Level1": "1"}},
}


@pytest.mark.parametrize("name", HOSTILE, ids=list(HOSTILE))
def test_hostile_options_are_refused_in_one_line_before_any_core_is_loaded(name: str, monkeypatch) -> None:
    options = dict(HOSTILE[name])
    state = options.pop("state", retrokit.State.DEFAULT)

    def no_core(*args, **kwargs):
        raise AssertionError("a core was loaded before the options were checked")

    monkeypatch.setattr(env_module, "Emulator", no_core)
    with pytest.raises(RetrokitError) as caught:
        retrokit.make(AIRSTRIKER, state, **options)
    assert isinstance(caught.value, (InvalidArgumentError, UnknownNameError))
    message = str(caught.value)
    assert "\n" not in message and "Expected" in message
    if name == "resize-method-misspelled":
        assert "Did you mean 'area'?" in message
    if name == "info-keys-unknown-field":
        assert "Did you mean 'score'?" in message


def test_make_vec_refuses_a_list_of_states_of_the_wrong_length() -> None:
    with pytest.raises(InvalidArgumentError, match="one state per env"):
        retrokit.make_vec(DASHER, 3, ["Zone1.Act1", "Zone2.Act1"])


@pytest.fixture(scope="module")
def patched() -> None:
    if built_core("genesis_plus_gx") is None:
        pytest.skip("the patched Genesis Plus GX is not built: run `retrokit build-core genesis_plus_gx` (CI does)")


@pytest.mark.parametrize("max_pool,drawn", [(False, 1), (True, 2)], ids=["last-frame", "max-pool-last-two"])
def test_only_the_frames_that_feed_an_observation_are_drawn(patched, max_pool: bool, drawn: int) -> None:
    env = retrokit.make(AIRSTRIKER, frameskip=SKIP, grayscale=True, resize=(84, 84), frame_stack=4, max_pool=max_pool)
    env.reset(seed=0)
    asked, before = env.emulator.av_asked, env.emulator.av_drawn
    steps = 25
    for _ in range(steps):
        env.step(env.action_space.sample())
    assert env.emulator.av_asked - asked == steps * SKIP  # the patched core asks every frame
    assert env.emulator.av_drawn - before == steps * drawn
    env.close()


def test_noop_starts_are_random_seeded_and_within_noop_max() -> None:
    env = retrokit.make(AIRSTRIKER, frameskip=SKIP, noop_max=30, grayscale=True)
    plain = retrokit.make(AIRSTRIKER, frameskip=SKIP, grayscale=True)
    runs = []
    for seed in (1, 1, 2, 3, 4):
        before = env.emulator.frame
        obs, _ = env.reset(seed=seed)
        # The reset ran the first frame once at make() already: what it runs now is the no-ops.
        runs.append((env.emulator.frame - before, obs.copy()))
    frames = [f for f, _ in runs]
    assert all(SKIP <= f <= 30 * SKIP and f % SKIP == 0 for f in frames), frames
    assert frames[0] == frames[1] and (runs[0][1] == runs[1][1]).all()  # the same seed, the same start
    assert len(set(frames)) > 1
    first, _ = plain.reset(seed=1)
    assert not (runs[0][1] == first).all()  # the no-ops moved the game on
    env.close()
    plain.close()


def test_reward_clip_gives_the_sign_or_a_bound() -> None:
    envs = {clip: retrokit.make(DASHER, frameskip=SKIP, reward_clip=clip) for clip in (False, True, 0.5)}
    for env in envs.values():
        env.reset(seed=0)
        env.action_space.seed(0)
    seen = set()
    for _ in range(50):  # enough random play to earn rewards; each step checks all three clips
        action = envs[False].action_space.sample()
        raw, sign, bound = (env.step(action)[1] for env in envs.values())
        assert sign == float(np.sign(raw)) and bound == min(max(raw, -0.5), 0.5)
        seen.add(np.sign(raw))
    assert seen - {0}, "the random play should have earned some reward"
    for env in envs.values():
        env.close()


def test_info_keys_choose_what_crosses_into_python() -> None:
    none = retrokit.make(AIRSTRIKER, frameskip=SKIP, info_keys=[])
    score = retrokit.make(AIRSTRIKER, frameskip=SKIP, info_keys=["score"])
    idle = np.zeros(none.action_space.shape, dtype=none.action_space.dtype)
    assert none.reset(seed=0)[1] == {} and none.step(idle)[4] == {}
    assert set(score.reset(seed=0)[1]) == {"score"} and set(score.step(idle)[4]) == {"score"}
    vec = retrokit.make_vec(AIRSTRIKER, 2, frameskip=SKIP, info_keys=["lives"])
    vec.reset(seed=0)
    info = vec.step(vec.action_space.sample())[4]
    assert set(info) == {"lives", "_lives"} and list(info["lives"]) == [none.reader.read()["lives"]] * 2
    quiet = retrokit.make_vec(AIRSTRIKER, 2, frameskip=SKIP, info_keys=[])
    assert quiet.reset(seed=0)[1] == {}
    for _ in range(3):
        assert quiet.step(quiet.action_space.sample())[4] == {}
    for env in (none, score, vec, quiet):
        env.close()


def test_state_weights_draw_a_state_at_each_reset_seeded() -> None:
    weights = {"Zone1.Act1": 1, "Zone2.Act1": 1, "Zone3.Act1": 0}
    env = retrokit.make(DASHER, weights, frameskip=SKIP)
    draws = []
    for seed in range(12):
        _, info = env.reset(seed=seed)
        draws.append(env.state_name)
        assert info["zone"] == int(env.state_name[4]) - 1  # the game is at the state drawn
    assert set(draws) == {"Zone1.Act1", "Zone2.Act1"}
    again = [env.reset(seed=seed) and env.state_name for seed in range(12)]
    assert again == draws
    env.close()


def test_make_vec_takes_one_state_per_env() -> None:
    states = ["Zone1.Act1", "Zone2.Act1", {"Zone3.Act1": 1}]
    vec = retrokit.make_vec(DASHER, 3, states, frameskip=SKIP)
    _, info = vec.reset(seed=0)
    assert [env.state_name for env in vec.envs] == ["Zone1.Act1", "Zone2.Act1", "Zone3.Act1"]
    assert list(info["zone"]) == [0, 1, 2]
    vec.close()


NATIVE_HOSTILE = {
    "crop-wrapping-around": (224, 320, 2**32 - 1, 1, 0, 0, 84, 84, 1, 1, 0, 1, 0),
    "crop-everything": (224, 320, 112, 112, 0, 0, 84, 84, 1, 1, 0, 1, 0),
    "zero-stack": (224, 320, 0, 0, 0, 0, 84, 84, 1, 1, 0, 0, 0),
    "unknown-method": (224, 320, 0, 0, 0, 0, 84, 84, 9, 1, 0, 1, 0),
    "no-resize-yet-another-size": (224, 320, 0, 0, 0, 0, 84, 84, 0, 1, 0, 1, 0),
    "huge-screen": (2**20, 320, 0, 0, 0, 0, 84, 84, 1, 1, 0, 1, 0),
}


@pytest.mark.parametrize("name", NATIVE_HOSTILE, ids=list(NATIVE_HOSTILE))
def test_the_native_host_checks_a_preprocessing_again(airstriker, name: str) -> None:
    with pytest.raises(InvalidArgumentError):
        airstriker.set_preprocess(NATIVE_HOSTILE[name])
    airstriker.run(0, 1)  # still the plain RGB screen
    assert airstriker.run(0, 1, np.zeros((224, 320, 3), np.uint8)) is True


def test_a_wrong_observation_buffer_is_refused(airstriker) -> None:
    airstriker.set_preprocess((224, 320, 0, 0, 0, 0, 84, 84, 1, 1, 0, 4, 0))
    with pytest.raises(InvalidArgumentError, match="observation buffer"):
        airstriker.run(0, 1, np.zeros((224, 320, 3), np.uint8))
    out = np.zeros((84, 84, 4), np.uint8)
    assert airstriker.run(0, 4, out) is True and out.any()
