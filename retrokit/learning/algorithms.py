"""The learning algorithms retrokit builds in, and how each declares its config's keys.

Each algorithm is a module named in :data:`ALGORITHMS` that defines, without
importing its library at module level:

- ``LIBRARY``: the library it trains with (``"stable-baselines3"``), for messages and ``policy.json``;
- ``KEYS``: its config's keys, a mapping of name to :class:`Key` (the loader checks every config against it);
- optionally ``check_values(values)``: the problem of keys taken together (``v_min`` above ``v_max``), as a
  sentence, or ``None``;
- ``observation_options(config)``: the native preprocessing options (``grayscale``, ``resize``, ...) the runner
  adds to a level's env for it;
- ``require()``: raise :class:`~retrokit.errors.MissingExtraError` if its library is not installed;
- ``play(env, budget, seed, setup)``: play (and learn on) one level's env for ``retrokit evaluate``;
- ``train(run)``: train one policy on a benchmark's training levels for ``retrokit train``
  (:class:`~retrokit.learning.trainrun.TrainRun`).
"""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass
from types import ModuleType
from typing import Any

from retrokit.errors import MissingExtraError, UnknownNameError, did_you_mean, install_extra

#: Every learning agent, by its ``--agent`` name: the module that implements it.
ALGORITHMS = {
    "ppo": "retrokit.learning.ppo",
    "rainbow": "retrokit.learning.rainbow",
}


@dataclass(frozen=True)
class Key:
    """One key of an agent's config: its type, its range, and what it means.

    Attributes:
        kind: ``int``, ``float`` (an int is taken too), ``bool`` or ``str``.
        help: What the key sets, for messages and docs.
        low: The smallest value allowed (numbers).
        high: The largest value allowed (numbers).
        choices: The values allowed (strings).
    """

    kind: type
    help: str
    low: float | None = None
    high: float | None = None
    choices: tuple[str, ...] | None = None

    def problem(self, value: Any) -> str | None:
        """Why ``value`` does not fit this key, or ``None`` if it does."""
        kind = self.kind
        fits = (
            isinstance(value, bool) if kind is bool
            else isinstance(value, int | float) and not isinstance(value, bool) if kind is float
            else isinstance(value, kind) and not isinstance(value, bool)
        )  # fmt: skip
        if not fits:
            return f"must be {'a whole number' if kind is int else 'a number' if kind is float else kind.__name__}"
        low = -math.inf if self.low is None else self.low
        high = math.inf if self.high is None else self.high
        if kind in (int, float) and not low <= value <= high:  # NaN too: no comparison holds
            return f"must be from {low:g} to {high:g}"
        if self.choices is not None and value not in self.choices:
            return f"must be one of {', '.join(self.choices)}"
        return None


#: The keys of what every learning agent's learner sees (:mod:`.task`): its reward's scale and its frames. Each
#: algorithm's table holds them, from here, so PPO and Rainbow cannot drift apart on them.
VIEW_KEYS: dict[str, Key] = {
    "reward_scale": Key(float, "what the learner's reward (the max-x reward) is multiplied by", 1e-9, 1e6),
    "frame_size": Key(int, "the side of the square frames the network sees, in pixels", 36, 256),
    "frame_stack": Key(int, "the frames stacked in an observation", 1, 16),
    "grayscale": Key(bool, "whether the frames are gray (else RGB)"),
    "network": Key(str, "the network", choices=("nature_cnn",)),
}


def require_libraries(agent: str, modules: dict[str, str]) -> None:
    """Raise :class:`~retrokit.errors.MissingExtraError` unless each module (import name: shown name) imports.

    The extra ``train`` has every learning agent's libraries; the message says to install torch's CPU build first.
    """
    import importlib

    try:
        for module in modules:
            importlib.import_module(module)
    except ImportError as exc:
        raise MissingExtraError(
            f"Expected {' and '.join(modules.values())} for --agent {agent}, but importing them failed ({exc}). "
            "Install torch's CPU build with `pip install torch --index-url https://download.pytorch.org/whl/cpu`, "
            f"then `{install_extra('train')}`."
        ) from None


def is_learning_agent(name: str) -> bool:
    """Whether ``--agent name`` is a built-in learning agent."""
    return name in ALGORITHMS


def algorithm(name: str) -> ModuleType:
    """The module of the learning agent ``name``.

    Raises:
        UnknownNameError: ``name`` is not a learning agent.
    """
    if name not in ALGORITHMS:
        raise UnknownNameError(
            f"Expected a learning agent ({', '.join(ALGORITHMS)}), got {name!r}." + did_you_mean(name, ALGORITHMS)
        )
    return importlib.import_module(ALGORITHMS[name])
