"""The built-in learning agents as ``retrokit evaluate`` calls them: ``agent(env, budget, seed, setup=...)``.

``retrokit evaluate --agent ppo`` names :func:`play` (``BUILTINS`` in
:mod:`retrokit.benchmark.agents`); the runner passes the level's
:class:`~retrokit.learning.setup.LearnerSetup` and hands the algorithm the
monitored env, whose every timestep counts toward the score.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from retrokit.errors import AgentError
from retrokit.learning.algorithms import algorithm

if TYPE_CHECKING:
    import gymnasium

    from retrokit.learning.setup import LearnerSetup


def play(env: gymnasium.Env, budget: int, seed: int, setup: LearnerSetup | None = None, **_: Any) -> None:
    """Play (and learn on) one level's env until its budget is spent, as ``setup`` says.

    Raises:
        AgentError: No setup was given (the agent was named as MODULE:CALLABLE, not by its name).
    """
    if setup is None:
        raise AgentError(
            "Expected a learning agent to be run by its name (--agent ppo), which prepares its config; it was "
            "called without one."
        )
    algorithm(setup.agent).play(env, budget, seed, setup)
