"""The stall watchdog: a level whose agent takes no timestep for too long is stopped.

An agent that sleeps, loops without stepping, steps ``env.unwrapped`` (which
the budget does not count) or swallows
:class:`~retrokit.benchmark.monitor.BudgetSpent` would otherwise hold its level,
and the evaluation, forever. Every backend feeds the watchdog the messages it
carries; a level is stalled when its count of timesteps has not grown for
``timeout`` seconds since its agent began to play. Before that, while its
process starts and makes its env (slow on a loaded machine), it has
:data:`START_SECONDS`, or the timeout if that is longer. The backend then stops the
level's process and fails the level with :meth:`Watchdog.error`: what was
finished is kept, and ``--resume`` plays the level again.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the level runner imports Gymnasium: `retrokit evaluate --help` needs only the default below
    from retrokit.benchmark.level import Message

#: The default stall timeout, in seconds: far above a step of any agent that learns as it plays.
DEFAULT_STALL_SECONDS = 600.0
#: The time a level's process may take to start and make its env.
START_SECONDS = 120.0


class Watchdog:
    """When each running level last took a timestep.

    Args:
        timeout: Seconds without a new timestep after which a level is stalled.
        budget: Timesteps per level (a stall at the budget means the agent went on after it).
    """

    def __init__(self, timeout: float, budget: int) -> None:
        self.timeout, self.budget = timeout, budget
        self._seen: dict[str, tuple[int, float, float]] = {}  # level -> (timesteps, when they last changed, limit)

    def start(self, level: str) -> None:
        """``level``'s process is starting: it has :data:`START_SECONDS` until its agent plays."""
        self._seen[level] = (0, time.monotonic(), max(START_SECONDS, self.timeout))

    def stop(self, level: str) -> None:
        """``level`` ended: it is no longer watched."""
        self._seen.pop(level, None)

    def see(self, message: Message) -> None:
        """Note a level's message: a start resets its clock, and so does a grown count of timesteps."""
        from retrokit.benchmark.level import Progress, Started

        if isinstance(message, Started):
            self._seen[message.level] = (0, time.monotonic(), self.timeout)
        elif isinstance(message, Progress) and message.level in self._seen \
                and message.timesteps != self._seen[message.level][0]:
            self._seen[message.level] = (message.timesteps, time.monotonic(), self.timeout)

    def timesteps(self, level: str) -> int:
        """The timesteps ``level`` was last seen to have taken."""
        return self._seen.get(level, (0, 0.0, 0.0))[0]

    def stalled(self) -> list[str]:
        """The watched levels with no new timestep for longer than their limit."""
        now = time.monotonic()
        return [level for level, (_, since, limit) in self._seen.items() if now - since > limit]

    def error(self, level: str) -> str:
        """The one-line reason a stalled level failed."""
        timesteps, _, limit = self._seen.get(level, (0, 0.0, self.timeout))
        if limit > self.timeout:
            return (f"Level {level} did not start: its process made no env and called no agent in {limit:g} s. "
                    "Check that the machine is not out of memory, and that importing the agent's module returns.")
        if timesteps >= self.budget:
            why = ("its budget was spent, but the agent went on: it must let BudgetSpent end its play "
                   "(an `except BaseException` or a bare `except:` swallows it)")
        else:
            why = (f"the agent took no timestep after step {timesteps:,} of {self.budget:,}: it sleeps, loops "
                   "without stepping, or steps env.unwrapped, which the budget does not count")
        return (f"Level {level} stalled and was stopped after {self.timeout:g} s without a timestep: {why}. "
                "If its steps are just slow, raise --stall-timeout.")
