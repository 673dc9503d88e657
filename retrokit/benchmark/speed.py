"""An evaluation's speed, and how long the paper's whole Sonic protocol takes at that speed.

A level is one agent's play from its first step to its last, so one process
plays it all: an agent that learns as it plays cannot have its episodes split
between processes. ``W`` workers therefore play ``L`` levels in
``ceil(L / W)`` rounds, and the protocol takes that many times one level's
time at the speed a level plays with ``W`` levels playing at once. A run
measures that speed on each level's own clock (from its env made to its budget
spent), so a loaded machine shows in it; start-up (a second or two a level)
is left out, next to a level of the paper's million timesteps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: The paper's protocol, as the ``sonic`` benchmark defines it (checked by the tests).
SONIC_LEVELS, SONIC_BUDGET = 11, 1_000_000


@dataclass(frozen=True)
class Speed:
    """How fast the levels of one run played.

    Attributes:
        steps: The timesteps of the levels finished in this run.
        seconds: Their play time, summed over the levels (each on its own clock).
        workers: The run's workers.
        at_once: The most levels that played at the same time (its workers, or fewer with fewer levels).
    """

    steps: int
    seconds: float
    workers: int
    at_once: int

    @property
    def level_rate(self) -> float:
        """Env steps per second of one level while it plays."""
        return self.steps / self.seconds if self.seconds > 0 else 0.0

    @property
    def rate(self) -> float:
        """Env steps per second of the run, with :attr:`at_once` levels playing."""
        return self.level_rate * self.at_once


def protocol_minutes(level_rate: float, workers: int, levels: int = SONIC_LEVELS, budget: int = SONIC_BUDGET) -> float:
    """Minutes to play ``levels`` levels of ``budget`` timesteps, ``workers`` at a time, each at ``level_rate``."""
    return math.ceil(levels / workers) * budget / level_rate / 60


def ceiling_minutes(bare_rate: float, cores: int, levels: int = SONIC_LEVELS, budget: int = SONIC_BUDGET) -> float:
    """Minutes of the protocol at the machine's ceiling: every core playing bare envs at ``bare_rate`` all along."""
    return levels * budget / (bare_rate * cores) / 60


def estimate_line(speed: Speed) -> str:
    """One line: the run's speed, and the Sonic protocol's time at it with the run's workers."""
    rounds = math.ceil(SONIC_LEVELS / speed.workers)
    minutes = protocol_minutes(speed.level_rate, speed.workers)
    line = (f"speed: {speed.level_rate:,.0f} env steps/s per level, {speed.rate:,.0f} in all with {speed.at_once} "
            f"level(s) at once; the Sonic protocol ({SONIC_LEVELS} test levels x {SONIC_BUDGET:,} timesteps) would "
            f"take about {minutes:,.0f} minutes here with --workers {speed.workers} ({rounds} round(s) of levels)")
    if speed.at_once < min(speed.workers, SONIC_LEVELS):
        line += f"; measured with {speed.at_once} level(s) at once, so with {speed.workers} at once it may be slower"
    return line + "."
