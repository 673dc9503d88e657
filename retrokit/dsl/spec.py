"""A scenario as read from a file, before compiling: plain data.

:mod:`retrokit.dsl.document` builds a :class:`ScenarioSpec` from retrokit YAML,
:mod:`retrokit.dsl.gymretro` from a Gym Retro ``scenario.json``; the compiler
turns either into running code.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from retrokit.dsl.source import Snippet

Scalar = int | float


@dataclass(frozen=True)
class Table:
    """A lookup table: ``level_end[zone, act]``.

    Attributes:
        name: The table's name in expressions.
        entries: Key tuple (one number per key part) to value.
        arity: How many key parts every lookup gives.
        by: Optional names of the key parts, e.g. ``("zone", "act")``; they
            name the parts in run-time errors.
        default: The value for a missing key; ``None`` makes a missing key a
            run-time error.
        origin: Points at the table's name where it is defined.
    """

    name: str
    entries: dict[tuple[Scalar, ...], Scalar]
    arity: int
    by: tuple[str, ...] | None
    default: Scalar | None
    origin: Snippet


@dataclass
class ScenarioSpec:
    """Everything a scenario says, with the source of each expression.

    Attributes:
        name: The scenario's name, for messages (``contest``).
        tables: Lookup tables by name.
        defines: Named intermediate expressions, by name.
        define_names: For each definition, a snippet pointing at its name.
        rewards: One reward expression per player.
        done: The done condition; ``None`` means never done.
        dones: One done condition per player, if given: a player whose
            condition holds is out of the game; the episode ends when
            ``done`` holds or every player is out.
        actions: Gym Retro-style button combinations, if given.
        jump: The button JERK jumps with, if given (else the system's).
        crop: ``(x, y, width, height)`` of the screen to keep, if given.
        reset_ram: What to write into RAM at each reset, drawn from the env's seeded generator: by console
            address, ``(type code, lowest, highest)`` (see :mod:`retrokit.envs.resetram`).
    """

    name: str
    tables: dict[str, Table] = field(default_factory=dict)
    defines: dict[str, Snippet] = field(default_factory=dict)
    define_names: dict[str, Snippet] = field(default_factory=dict)
    rewards: list[Snippet] = field(default_factory=list)
    done: Snippet | None = None
    dones: list[Snippet] = field(default_factory=list)
    actions: list | None = None
    jump: str | None = None
    crop: tuple[int, int, int, int] | None = None
    reset_ram: dict[int, tuple[str, int, int]] = field(default_factory=dict)
