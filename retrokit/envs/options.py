"""Checking what ``retrokit.make`` is given, before anything is built.

:func:`make_arguments` checks the game, state and scenario and every keyword
option of :class:`~retrokit.envs.env.RetroEnv`, and normalises them: numpy
integers and floats become Python ones, numbers that the native host cannot
hold are refused, a misspelled keyword gets a did-you-mean. Every refusal is
an :class:`~retrokit.errors.InvalidArgumentError` (or, for an unknown keyword,
an :class:`~retrokit.errors.UnknownNameError`) saying what was expected,
what was found and how to fix it, never a raw ``TypeError``.
"""

from __future__ import annotations

import enum
import math
import numbers
import os
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from retrokit.data.games import Game
from retrokit.envs.actions import ACTION_TYPES
from retrokit.envs.viewer import require_human
from retrokit.errors import InvalidArgumentError, UnknownNameError, did_you_mean, shown
from retrokit.paths import writable_folder

#: The native host counts frames in a C int.
MAX_FRAMESKIP = 2**31 - 1
#: Steps are counted in 64 bits.
MAX_STEPS = 2**63 - 1

OBS_TYPES = ("rgb", "ram")
RENDER_MODES = ("rgb_array", "human")


def _integer(name: str, value: object, low: int, high: int) -> int:
    """A whole number (Python or numpy, never a bool) in [low, high]."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise InvalidArgumentError(
            f"Expected {name} to be a whole number, got {shown(value)} ({type(value).__name__}); "
            f"pass e.g. {name}={low}."
        )
    number = int(value)
    if not low <= number <= high:
        raise InvalidArgumentError(f"Expected {name} from {low} to {high}, got {number}; pass a value in that range.")
    return number


def _frameskip(value: object) -> int:
    return _integer("frameskip", value, 1, MAX_FRAMESKIP)


def _players(value: object) -> int:
    return _integer("players", value, 1, 2**16)


def check_num_envs(value: object) -> int:
    """The number of envs of a vector env: a whole number (Python or numpy) from 1 up.

    Raises:
        InvalidArgumentError: It is not one (``2.5``, ``"2"``, ``True``, ``0``).
    """
    return _integer("num_envs", value, 1, MAX_STEPS)


def _max_episode_steps(value: object) -> int | None:
    return None if value is None else _integer("max_episode_steps", value, 1, MAX_STEPS)


def finite_real(value: object) -> float | None:
    """``value`` as a finite float, or ``None``: a bool, no real number, infinite, NaN, or an int past a float's range."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        return None
    try:
        number = float(value)
    except OverflowError:  # float(10**400)
        return None
    return number if math.isfinite(number) else None


def _sticky_prob(value: object) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise InvalidArgumentError(
            f"Expected sticky_prob to be a number in [0, 1], got {shown(value)} ({type(value).__name__}); "
            f"pass e.g. sticky_prob=0.25."
        )
    prob = float(value)
    if not (math.isfinite(prob) and 0.0 <= prob <= 1.0):
        raise InvalidArgumentError(f"Expected sticky_prob in [0, 1], got {prob}; pass a probability, e.g. 0.25.")
    return prob


def _choice(name: str, choices: tuple[str, ...], optional: bool = False) -> Callable[[object], str | None]:
    def check(value: object) -> str | None:
        if value is None and optional:
            return None
        if isinstance(value, str) and value in choices:
            return value
        hint = did_you_mean(value, choices) if isinstance(value, str) else _enum_hint(name, value, choices)
        allowed = ", ".join(repr(c) for c in choices) + (" or None" if optional else "")
        raise InvalidArgumentError(f"Expected {name} to be one of {allowed}, got {shown(value)}.{hint}")

    return check


#: stable-retro's enum members whose retrokit value is not their name in lower case.
_ENUM_VALUES = {"IMAGE": "rgb"}


def _enum_hint(name: str, value: object, choices: tuple[str, ...]) -> str:
    """For an enum member such as stable-retro's ``Actions.DISCRETE``: the string retrokit takes instead."""
    if not isinstance(value, enum.Enum):
        return ""
    equivalent = _ENUM_VALUES.get(value.name, value.name.lower())
    if equivalent not in choices:
        return ""
    return f" retrokit takes strings, not stable-retro's enums: pass {name}={equivalent!r} for {type(value).__name__}.{value.name}."


def _render_mode(value: object) -> str | None:
    mode = _choice("render_mode", RENDER_MODES, optional=True)(value)
    if mode == "human":
        require_human()  # at make(), not at the first reset, and with how to install it
    return mode


def _record(value: object) -> str | os.PathLike[str] | None:
    if value is None:
        return None
    if isinstance(value, (str, os.PathLike)) and os.fspath(value):
        # Made and tried now, not at the first reset(): a file in the way, a name too long, a NUL byte or a
        # folder that cannot be written is an error where the folder was given.
        writable_folder(os.fspath(value), "to record movies into (make()'s record=)")
        return value
    raise InvalidArgumentError(
        f"Expected record to be a folder path (str or os.PathLike) or None, got {shown(value)}; "
        f"pass e.g. record='movies'."
    )


def _flag(name: str) -> Callable[[object], bool]:
    def check(value: object) -> bool:
        if isinstance(value, (bool, np.bool_)):
            return bool(value)
        raise InvalidArgumentError(f"Expected {name} to be True or False, got {shown(value)}.")

    return check


def _core_options(value: object) -> dict[str, str] | None:
    if value is None:
        return None
    if isinstance(value, Mapping) and all(isinstance(k, str) and isinstance(v, str) for k, v in value.items()):
        return dict(value)
    raise InvalidArgumentError(
        f"Expected options to map core option names to values, both str, got {shown(value)}; "
        f"pass e.g. options={{'genesis_plus_gx_region_detect': 'ntsc-u'}}."
    )


#: The observation's resampling methods (OpenCV's INTER_AREA, INTER_LINEAR, INTER_NEAREST).
RESIZE_METHODS = ("area", "bilinear", "nearest")
#: The largest side of a resized observation, the most frames stacked, and the most no-op steps at reset.
MAX_SIDE = 4096
MAX_FRAME_STACK = 64
MAX_NOOPS = 10_000


def _whole_tuple(name: str, value: object, length: int, low: int, example: str) -> tuple[int, ...] | None:
    """``None``, or a tuple or list of ``length`` whole numbers of at least ``low`` (at most MAX_SIDE * 4)."""
    if value is None:
        return None
    if not isinstance(value, (tuple, list)) or len(value) != length:
        raise InvalidArgumentError(
            f"Expected {name} to be a tuple of {length} whole numbers or None, got {shown(value)}; pass e.g. "
            f"{name}={example}."
        )
    return tuple(_integer(f"each number of {name}", v, low, MAX_SIDE * 4) for v in value)


def _resize(value: object) -> tuple[int, int] | None:
    size = _whole_tuple("resize", value, 2, 1, "(84, 84)")
    if size is not None and max(size) > MAX_SIDE:
        raise InvalidArgumentError(f"Expected resize's height and width up to {MAX_SIDE}, got {size}; pass e.g. (84, 84).")
    return size  # type: ignore[return-value]


def _crop(value: object) -> tuple[int, int, int, int] | None:
    return _whole_tuple("crop", value, 4, 0, "(0, 16, 0, 0) (pixels off the top, bottom, left and right)")  # type: ignore[return-value]


def _frame_stack(value: object) -> int:
    return _integer("frame_stack", value, 1, MAX_FRAME_STACK)


def _noop_max(value: object) -> int:
    return _integer("noop_max", value, 0, MAX_NOOPS)


def _reward_clip(value: object) -> bool | float:
    """False (off), True (the reward's sign, as Atari agents clip) or a bound c > 0 (clip to [-c, c])."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    bound = finite_real(value)
    if bound is not None and bound > 0:
        return bound
    raise InvalidArgumentError(
        f"Expected reward_clip to be False, True (the reward's sign) or a finite bound above 0, got {shown(value)}; "
        f"pass e.g. reward_clip=True or reward_clip=1.0."
    )


def _info_keys(value: object) -> tuple[str, ...] | None:
    """``None`` (every field), or a list of field names (empty: no info at all)."""
    if value is None:
        return None
    if isinstance(value, (list, tuple)) and all(isinstance(k, str) for k in value):
        return tuple(dict.fromkeys(value))
    raise InvalidArgumentError(
        f"Expected info_keys to be a list of field names (empty for no info) or None for every field, got "
        f"{shown(value)}; pass e.g. info_keys=['score'] or info_keys=[]."
    )


#: Every keyword option of RetroEnv, and how it is checked (tests check this matches RetroEnv).
OPTIONS: dict[str, Callable[[Any], Any]] = {
    "obs_type": _choice("obs_type", OBS_TYPES),
    "action_type": _choice("action_type", ACTION_TYPES),
    "frameskip": _frameskip,
    "sticky_prob": _sticky_prob,
    "max_episode_steps": _max_episode_steps,
    "players": _players,
    "render_mode": _render_mode,
    "record": _record,
    "scenario_every_frame": _flag("scenario_every_frame"),
    "skip_video": _flag("skip_video"),
    "options": _core_options,
    # Observation preprocessing, done natively (retrokit/envs/preprocessing.py).
    "grayscale": _flag("grayscale"),
    "resize": _resize,
    "resize_method": _choice("resize_method", RESIZE_METHODS),
    "crop": _crop,
    "frame_stack": _frame_stack,
    "channels_first": _flag("channels_first"),
    "max_pool": _flag("max_pool"),
    # Episodes and what a step hands back.
    "noop_max": _noop_max,
    "reset_frame": _flag("reset_frame"),
    "reward_clip": _reward_clip,
    "info_keys": _info_keys,
}


def check_options(options: Mapping[str, Any]) -> dict[str, Any]:
    """Check and normalise RetroEnv's keyword options.

    Raises:
        UnknownNameError: A keyword is not an option (with the closest one).
        InvalidArgumentError: A value has the wrong type or range.
    """
    check_names(options)
    return {name: OPTIONS[name](value) for name, value in options.items()}


#: stable-retro's keywords of ``make`` that retrokit spells otherwise, and what to write instead.
STABLE_RETRO_KEYWORDS = {
    "use_restricted_actions": "use action_type='filtered', 'all', 'discrete' or 'multi_discrete' for "
    "retro.Actions.FILTERED, ALL, DISCRETE or MULTI_DISCRETE",
    "inttype": "leave it out: retrokit looks for a game in every integration folder, and RETROKIT_GAMES adds your "
    "own (docs/from-stable-retro.md)",
    "info": "leave it out: a game's RAM fields come from its game.yaml or data.json, and info holds them all",
}


def check_names(options: Mapping[str, Any]) -> None:
    """Refuse a keyword that is no option of RetroEnv, with the closest one, or retrokit's name for stable-retro's.

    Raises:
        UnknownNameError: A keyword is not an option.
    """
    for name in options:
        if name in STABLE_RETRO_KEYWORDS:
            raise UnknownNameError(
                f"Expected a keyword option of retrokit.make, got stable-retro's {name!r}; "
                f"{STABLE_RETRO_KEYWORDS[name]}."
            )
        if name not in OPTIONS:
            raise UnknownNameError(
                f"Expected a keyword option of retrokit.make ({', '.join(OPTIONS)}), got {name!r}."
                + did_you_mean(name, OPTIONS)
            )


def make_arguments(game: object, state: object, scenario: object, options: Mapping[str, Any]) -> dict[str, Any]:
    """Check what ``retrokit.make`` was given before RetroEnv takes it; return RetroEnv's keyword arguments.

    The options' values are checked by RetroEnv itself (:func:`check_options`),
    so that an env made directly follows the same rules; here only their names.

    Args:
        game: The game's name, or a :class:`~retrokit.data.games.Game`.
        state: A state name or ``.state`` path, a :class:`~retrokit.envs.env.State`, or ``None``.
        scenario: A scenario name or path, a scenario dict, or ``None``.
        options: The keyword options.

    Raises:
        UnknownNameError: A keyword is not an option.
        InvalidArgumentError: An argument has the wrong type or range.
    """
    if not (isinstance(game, Game) or (isinstance(game, str) and game)):
        raise InvalidArgumentError(
            f"Expected game to be a game's name (str) or a Game, got {shown(game)}; pass e.g. 'Airstriker-Genesis' "
            f"(`retrokit games` lists them)."
        )
    if not (state is None or isinstance(state, (str, os.PathLike, enum.Enum, Mapping))):
        raise InvalidArgumentError(
            f"Expected state to be a state's name, a .state path, retrokit.State, a mapping of state names to "
            f"weights (one drawn at each reset) or None, got {shown(state)}."
        )
    if not (scenario is None or isinstance(scenario, (str, os.PathLike, Mapping))):
        raise InvalidArgumentError(
            f"Expected scenario to be a scenario's name, a .yaml or .json path, a dict or None, got {shown(scenario)}."
        )
    check_names(options)
    return {"game": game, "state": state, "scenario": scenario, **options}


def check_seed(seed: object) -> int | None:
    """Check a ``reset(seed=...)``: every env's reset goes through this one check.

    Returns:
        The seed as a Python int (numpy integers are taken, as ``make`` takes
        them for its options), or ``None``.

    Raises:
        InvalidArgumentError: The seed is not a whole number of 0 or more (or None).
    """
    if seed is None:
        return None
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, numbers.Integral):
        raise InvalidArgumentError(
            f"Expected seed to be a whole number of 0 or more, or None, got {shown(seed)} ({type(seed).__name__}); "
            f"pass e.g. seed=0."
        )
    if seed < 0:
        raise InvalidArgumentError(f"Expected a seed of 0 or more, got {int(seed)}; pass e.g. seed=0.")
    return int(seed)


def check_crop(crop: tuple[int, int, int, int] | None, screen: tuple[int, int]) -> None:
    """Refuse a scenario's crop ``(x, y, width, height)`` that leaves nothing of a ``(height, width)`` screen.

    A width or height of 0 reaches the screen's edge, as in Gym Retro, so only
    a corner past the screen's right or bottom edge leaves nothing.
    """
    if crop is None:
        return
    x, y, _, _ = crop
    height, width = screen
    if x >= width or y >= height:
        raise InvalidArgumentError(
            f"Expected the scenario's crop [x, y, width, height] to keep part of the {width}x{height} screen, "
            f"got {list(crop)}; fix 'crop' in the scenario (x below {width}, y below {height})."
        )
