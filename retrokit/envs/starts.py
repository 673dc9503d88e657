"""Where episodes start: one state, a state drawn at each reset, or (in a vector env) one state per env.

``retrokit.make(game, state)`` takes, besides one state, a mapping of state
names to weights: each ``reset()`` draws one of them with those weights,
from the env's seeded generator, so a seeded run draws the same states.
``retrokit.make_vec(game, n, state)`` also takes a list of ``n`` states (each
a name, a path, ``None`` or such a mapping): env ``i`` starts at the ``i``-th.
"""

from __future__ import annotations

import numbers
import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from retrokit.envs.options import finite_real
from retrokit.errors import InvalidArgumentError, shown


def check_weights(state: Mapping[Any, Any]) -> dict[str, float]:
    """Check a mapping of state names (or ``.state`` paths) to weights; return it with float weights.

    Raises:
        InvalidArgumentError: It is empty, a key is not a name or path, a weight is not a number of 0 or
            more, or they are all 0.
    """
    if not state:
        raise InvalidArgumentError(
            "Expected state weights to name at least one state, got an empty mapping; pass e.g. "
            "state={'Level1': 1, 'Level2': 1}."
        )
    weights: dict[str, float] = {}
    for name, weight in state.items():
        if not isinstance(name, (str, os.PathLike)) or not os.fspath(name):
            raise InvalidArgumentError(
                f"Expected each key of the state weights to be a state's name or a .state path, got {shown(name)}."
            )
        if isinstance(weight, (bool, np.bool_)) or not isinstance(weight, numbers.Real):
            raise InvalidArgumentError(
                f"Expected the weight of state {os.fspath(name)!r} to be a number of 0 or more, got {shown(weight)}."
            )
        value = finite_real(weight)
        if value is None or value < 0:
            raise InvalidArgumentError(
                f"Expected the weight of state {os.fspath(name)!r} to be a finite number of 0 or more, got "
                f"{shown(weight)}."
            )
        weights[os.fspath(name)] = value
    if sum(weights.values()) <= 0:
        raise InvalidArgumentError(
            f"Expected some state weight above 0, got {shown(state)}; give the states to draw a weight above 0."
        )
    return weights


def probabilities(weights: Mapping[str, float]) -> np.ndarray:
    """The weights as probabilities that sum to 1."""
    values = np.array(list(weights.values()), dtype=np.float64)
    values = values / values.max()  # first: weights near the float's limit would sum to infinity
    return values / values.sum()


def per_env_states(state: object, num_envs: int) -> list[Any]:
    """The start state of each env of a vector env: ``state`` for all, or a list's ``i``-th for env ``i``.

    Raises:
        InvalidArgumentError: A list whose length is not ``num_envs``.
    """
    if isinstance(state, Sequence) and not isinstance(state, (str, bytes)):
        if len(state) != num_envs:
            raise InvalidArgumentError(
                f"Expected one state per env ({num_envs}), got a list of {len(state)}; pass {num_envs} states, or "
                "one state (or a mapping of states to weights) for every env."
            )
        return list(state)
    return [state] * num_envs
