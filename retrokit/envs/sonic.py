"""The Sonic benchmark of "Gotta Learn Fast" (Nichol et al., 2018), as a preset.

58 levels of Sonic 1, Sonic 2 and Sonic 3 & Knuckles, split 47 for training
and 11 for testing. Each env has the benchmark's rules: sticky frame skip 4
with p = 0.25, episodes of 4500 steps, and the contest scenario, whose reward
is 9000 for reaching the level's end plus a completion bonus of up to 1000.
The scenario runs after every frame, as the paper's frame-skip wrapper did.

The ROMs are the user's to import (``retrokit import``); the states are the
ones the stable-retro wheel ships.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from retrokit.data.games import find_game
from retrokit.data.sonic_levels import (  # noqa: F401 - named here too, where users look: retrokit.sonic.levels()
    GAMES,
    TEST_LEVELS,
    levels,
    test_levels,
    train_levels,
)
from retrokit.envs.env import RetroEnv
from retrokit.envs.options import check_options
from retrokit.errors import EnvError, InvalidArgumentError, StateNotFoundError, did_you_mean

#: The baselines' 7 button combinations.
ACTIONS = (("LEFT",), ("RIGHT",), ("LEFT", "DOWN"), ("RIGHT", "DOWN"), ("DOWN",), ("DOWN", "B"), ("B",))
#: The same with the no-op first: 8 actions.
ACTIONS_WITH_NOOP = ((),) + ACTIONS

FRAMESKIP = 4
STICKY_PROB = 0.25
MAX_EPISODE_STEPS = 4500
#: The benchmark's rules, as ``make()`` options: what :func:`make` gives every level (its options may
#: add to them, e.g. ``grayscale=True, resize=(84, 84), frame_stack=4, max_pool=True``).
RULES = {
    "frameskip": FRAMESKIP,
    "sticky_prob": STICKY_PROB,
    "max_episode_steps": MAX_EPISODE_STEPS,
    "scenario_every_frame": True,
}


def press_each(env: gymnasium.Env, combos: tuple[tuple[str, ...], ...]) -> list[np.ndarray]:
    """The action array of each button combination, for an env (or a vector env's env) with ``action_type="all"``.

    What :class:`Discretizer` sends; a vector env's learner maps its choices through the same arrays.

    Raises:
        InvalidArgumentError: The env's actions are not ``"all"``.
        UnknownNameError: A button is not one of the system's.
    """
    base: RetroEnv = env.unwrapped  # type: ignore[assignment]
    if base.actions.action_type != "all":
        raise InvalidArgumentError(f"Expected an env with action_type='all', got {base.actions.action_type!r}.")
    return [base.actions.press(combo) for combo in combos]  # type: ignore[misc]


class Discretizer(gymnasium.ActionWrapper):
    """Turns a Discrete choice into one of a list of button combinations.

    Args:
        env: A :class:`RetroEnv` with ``action_type="all"``.
        combos: Button-name combinations, one per action.
    """

    def __init__(self, env: gymnasium.Env, combos: tuple[tuple[str, ...], ...]) -> None:
        super().__init__(env)
        self._arrays = press_each(env, combos)
        self.combos = combos
        self.action_space = spaces.Discrete(len(combos))

    def action(self, action: int) -> np.ndarray:
        return self._arrays[int(action)]


class MaxProgress:
    """One episode's max-x reward: a step earns how far it takes the episode's best progress, never less than 0.

    The baselines' reward preprocessing. Progress is the x of a RAM field (a
    benchmark's ``learning.x``) or, without one, the episode's reward so far
    (the Sonic contest's reward is progress along the level): going back
    costs nothing, and earns nothing again when the agent covers the same
    ground a second time.
    """

    def __init__(self) -> None:
        self.best = self.current = 0.0

    def start(self, progress: float = 0.0) -> None:
        """Begin an episode at ``progress`` (its x at the start, or 0 for the reward so far)."""
        self.best = self.current = float(progress)

    def advance(self, progress: float) -> float:
        """The step's reward: how far ``progress`` (now) passes the best so far."""
        gain = max(0.0, float(progress) - self.best)
        self.best, self.current = max(self.best, float(progress)), float(progress)
        return gain


class AllowBacktracking(gymnasium.Wrapper):
    """Rewards only new progress: the step's gain past the best x so far (:class:`MaxProgress`).

    The baselines' preprocessing: with the contest reward (progress), going
    back and forth no longer costs reward, so agents may backtrack freely.

    Args:
        env: The env.
        x: A field of the game (in ``info``) that is the player's x; ``None``: the episode's reward so far.
    """

    def __init__(self, env: gymnasium.Env, x: str | None = None) -> None:
        super().__init__(env)
        self.x = x
        self._progress = MaxProgress()

    def reset(self, **kwargs: Any):
        obs, info = self.env.reset(**kwargs)
        self._progress.start(progress_of(info, self.x))
        return obs, info

    def step(self, action: Any):
        obs, reward, terminated, truncated, info = self.env.step(action)
        now = self._progress.current + float(reward) if self.x is None else progress_of(info, self.x)
        return obs, self._progress.advance(now), terminated, truncated, info


def progress_of(info: Mapping[str, Any], x: str | None) -> float:
    """The field ``x`` of a step's ``info`` (0.0 without ``x``: progress is then the reward so far).

    Raises:
        EnvError: ``info`` has no field ``x`` (the env's ``info_keys`` leave it out).
    """
    if x is None:
        return 0.0
    try:
        return float(info[x])
    except KeyError:
        raise EnvError(
            f"Expected the field {x!r} (the x of the max-x reward) in the step's info, but it has "
            f"{', '.join(sorted(map(str, info))) or 'none'}; keep it in info_keys."
        ) from None


def make(
    game: str,
    state: str,
    *,
    scenario: str = "contest",
    noop: bool = False,
    allow_backtracking: bool = False,
    **options: Any,
) -> gymnasium.Env:
    """Make a benchmark level's env with the paper's rules.

    Args:
        game: One of :data:`GAMES`.
        state: The level, e.g. ``"GreenHillZone.Act1"``.
        scenario: ``"contest"`` (the benchmark's) or ``"xpos"``.
        noop: Use the 8 actions that include the no-op instead of the 7.
        allow_backtracking: Reward only progress past the best x so far.
        **options: Other :class:`RetroEnv` options (``obs_type``, ``render_mode``, ``record``...).

    Raises:
        RomNotFoundError: The game's ROM has not been imported; the message says how.
    """
    if game not in GAMES:
        raise InvalidArgumentError(f"Expected one of the benchmark's games {GAMES}, got {game!r}." + did_you_mean(game, GAMES))
    states = find_game(game).states
    if state not in states:
        raise StateNotFoundError(f"Expected a level of {game} ({', '.join(sorted(states))}), got {state!r}." + did_you_mean(state, states))
    settings = {**RULES, **options, "action_type": "all"}
    env: gymnasium.Env = RetroEnv(game, state, scenario, **check_options(settings))
    env = Discretizer(env, ACTIONS_WITH_NOOP if noop else ACTIONS)
    if allow_backtracking:
        env = AllowBacktracking(env)
    return env
