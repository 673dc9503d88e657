"""An evaluation's speed, and how long the paper's whole Sonic protocol takes at that speed.

A level is one agent's play from its first step to its last, so one process
plays it all: an agent that learns as it plays cannot have its episodes split
between processes. ``W`` workers therefore play ``L`` levels in
``ceil(L / W)`` rounds. A run measures the speed of a level on its own clock
(from its env made to its budget spent), so a loaded machine shows in it;
start-up (a second or two a level) is left out, next to a level of the
paper's million timesteps.

A round's levels share the cores: a level with a core to itself plays at the
core's rate, and ``k`` levels on ``c < k`` cores each at ``c / k`` of it. So
with as many workers as cores the last round may leave cores idle (11 levels
on 2: the 11th plays alone), and a few more workers, so that every round has a
level for each core, keep them all busy. Measured on Dasher's 3 test levels
on 2 cores: ``--workers 3`` took 46 s where ``--workers 2`` took 55, the
processes sharing the cores costing 4% of the throughput.
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
        cores: The CPUs the run could use.
    """

    steps: int
    seconds: float
    workers: int
    at_once: int
    cores: int

    @property
    def level_rate(self) -> float:
        """Env steps per second of one level while it plays."""
        return self.steps / self.seconds if self.seconds > 0 else 0.0

    @property
    def rate(self) -> float:
        """Env steps per second of the run, with :attr:`at_once` levels playing."""
        return self.level_rate * self.at_once

    @property
    def core_rate(self) -> float:
        """Env steps per second of a level with a core to itself: more levels than cores shared them."""
        return self.level_rate * max(1.0, self.at_once / max(self.cores, 1))


def protocol_minutes(
    core_rate: float, workers: int, cores: int, levels: int = SONIC_LEVELS, budget: int = SONIC_BUDGET
) -> float:
    """Minutes to play ``levels`` levels of ``budget`` timesteps, ``workers`` at a time on ``cores`` cores.

    Each round's levels play at ``core_rate`` with a core each, or share the
    cores when they outnumber them; a round lasts as long as its levels.
    """
    minutes, left = 0.0, levels
    while left > 0:
        playing = min(workers, left)
        minutes += budget / (core_rate * min(1.0, cores / playing)) / 60
        left -= playing
    return minutes


def ceiling_minutes(bare_rate: float, cores: int, levels: int = SONIC_LEVELS, budget: int = SONIC_BUDGET) -> float:
    """Minutes of the protocol at the machine's ceiling: every core playing bare envs at ``bare_rate`` all along."""
    return levels * budget / (bare_rate * cores) / 60


def busy_workers(cores: int, levels: int = SONIC_LEVELS) -> int:
    """The fewest workers, at least ``cores``, for which every round of levels (the last included) busies every core.

    That is, ``levels`` divides into rounds of ``workers`` with a last round of
    ``cores`` levels or more; ``levels`` itself always does.
    """
    cores = max(1, min(cores, levels))
    return next(w for w in range(cores, levels + 1) if levels % w == 0 or levels % w >= cores)


def estimate_line(speed: Speed, *, sonic: bool = True) -> str:
    """One line: the run's speed and, for a run of the Sonic benchmark, the whole protocol's time at it.

    Args:
        speed: The run's speed.
        sonic: Whether the run was of the ``sonic`` benchmark; for another, the protocol's
            time says nothing, so the line gives the speed alone.
    """
    line = f"speed: {speed.level_rate:,.0f} env steps/s per level, {speed.rate:,.0f} in all with {speed.at_once} level(s) at once"
    if not sonic:
        return line + "."
    rounds = math.ceil(SONIC_LEVELS / speed.workers)
    minutes = protocol_minutes(speed.core_rate, speed.workers, speed.cores)
    line += (f"; the Sonic protocol ({SONIC_LEVELS} test levels x {SONIC_BUDGET:,} timesteps) would "
             f"take about {minutes:,.0f} minutes here with --workers {speed.workers} ({rounds} round(s) of levels)")
    if speed.at_once < min(speed.workers, SONIC_LEVELS):
        line += f"; measured with {speed.at_once} level(s) at once, so with {speed.workers} at once it may be slower"
    last = SONIC_LEVELS - (rounds - 1) * speed.workers
    if last < min(speed.cores, speed.workers):
        better = busy_workers(speed.cores)
        line += (f"; its last round plays {last} level(s) on {speed.cores} cores, leaving "
                 f"{min(speed.cores, speed.workers) - last} idle: --workers {better} keeps every core busy in every "
                 f"round, about {protocol_minutes(speed.core_rate, better, speed.cores):,.0f} minutes")
    return line + "."
