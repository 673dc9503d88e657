"""stable-retro's enums, with its names and values: where an env starts, its actions and its observations."""

from __future__ import annotations

from enum import Enum


class State(Enum):
    """Special start states: the game's default state, or power-on (no state, no console reset)."""

    DEFAULT = -1
    NONE = 0


class Observations(Enum):
    """What an observation is: the screen (``IMAGE``) or the RAM as ``get_ram()`` gives it (``RAM``)."""

    IMAGE = 0
    RAM = 1


class Actions(Enum):
    """The action space: every button (``ALL``), the scenario's allowed ones (``FILTERED``), or their combinations."""

    ALL = 0
    FILTERED = 1
    DISCRETE = 2
    MULTI_DISCRETE = 3


#: stable-retro's action kinds -> retrokit's ``action_type``.
ACTION_TYPES = {
    Actions.ALL: "all", Actions.FILTERED: "filtered", Actions.DISCRETE: "discrete",
    Actions.MULTI_DISCRETE: "multi_discrete",
}  # fmt: skip
#: stable-retro's observation kinds -> retrokit's ``obs_type``.
OBS_TYPES = {Observations.IMAGE: "rgb", Observations.RAM: "ram"}
