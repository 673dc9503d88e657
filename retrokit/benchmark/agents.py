"""Agents: how they are named on the command line, and the ``random`` baseline.

An agent is a callable ``agent(env, budget, seed)``, called once per level. It
plays the level's env (a Gymnasium env, wrapped in a
:class:`~retrokit.benchmark.monitor.Monitor`) with ``reset`` and ``step`` until
the budget is spent, when ``step`` raises
:class:`~retrokit.benchmark.monitor.BudgetSpent`; the runner catches it. So any
Gymnasium policy fits in a few lines (docs/evaluate.md has a Stable-Baselines3
PPO). ``seed`` seeds the agent's own randomness; the env's first reset is
already seeded by the runner.

On the command line an agent is ``random``, ``jerk``, a learning agent
(``ppo``: :mod:`retrokit.learning`, which the runner also passes its setup as
``agent(env, budget, seed, setup=...)``), or ``MODULE:CALLABLE`` where
``MODULE`` is an importable module or a ``.py`` file.
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from retrokit.errors import UnknownNameError, did_you_mean

if TYPE_CHECKING:  # only annotations use it: the agent check's child (_CHECK) need not import it (~0.25 CPU-s)
    import gymnasium

BUILTINS = {
    "random": "retrokit.benchmark.agents:random_agent",
    "jerk": "retrokit.benchmark.jerk:jerk",
    # The learning agents (retrokit.learning): called with the level task's setup (config, start policy).
    "ppo": "retrokit.learning.play:play",
    "rainbow": "retrokit.learning.play:play",
}


class Agent(Protocol):
    """Plays one level's env until its budget is spent."""

    def __call__(self, env: gymnasium.Env, budget: int, seed: int) -> None: ...


def random_agent(env: gymnasium.Env, budget: int, seed: int) -> None:
    """Sample every action uniformly from the action space (seeded by the runner).

    Console switches (the 2600's SELECT and RESET, ...: ``switches`` in the system's
    descriptor) are left alone: pressed at random they end or restart the game.
    """
    actions = getattr(env.unwrapped, "actions", None)
    leave = getattr(actions, "leave_switches", lambda action: action)
    env.reset()
    while True:
        _, _, terminated, truncated, _ = env.step(leave(env.action_space.sample()))
        if terminated or truncated:
            env.reset()


def resolve_agent(spec: str) -> Callable[..., None]:
    """Return the agent named ``random``, ``jerk`` or ``MODULE:CALLABLE``.

    Raises:
        UnknownNameError: The name is none of those, or the module or callable cannot be found.
    """
    target = BUILTINS.get(spec, spec)
    module_name, sep, attribute = target.partition(":")
    if not sep or not module_name or not attribute:
        raise UnknownNameError(
            f"Expected an agent ({', '.join(BUILTINS)}, or MODULE:CALLABLE), got {spec!r}." + did_you_mean(spec, BUILTINS)
        )
    try:
        module = _load_module(module_name)
    except (Exception, SystemExit, KeyboardInterrupt) as exc:  # noqa: BLE001 - user code: its failure is its own
        raise UnknownNameError(
            f"Expected the agent {spec!r} to name an importable module, but importing {module_name!r} failed: "
            f"{type(exc).__name__}: {exc}. Check the name, or give a path to a .py file."
        ) from None
    agent = getattr(module, attribute, None)
    if not callable(agent):
        names = [n for n in vars(module) if not n.startswith("_") and callable(getattr(module, n))]
        raise UnknownNameError(
            f"Expected {module_name!r} to define a callable {attribute!r} (agent(env, budget, seed)), but it does not."
            + did_you_mean(attribute, names)
        )
    return agent


_CHECK = """
import json, sys
sys.path[:] = json.loads(sys.argv[2])
from retrokit.benchmark.agents import resolve_agent
from retrokit.errors import RetrokitError
try:
    resolve_agent(sys.argv[1])
except RetrokitError as exc:
    print(exc, file=sys.stderr)
    sys.exit(2)
print("agent ok", flush=True)
"""
AGENT_IMPORT_TIMEOUT = 600.0
"""Seconds an agent's module may take to import in the check (a deep-learning library takes tens)."""


def check_agent(spec: str) -> None:
    """Import the agent ``spec`` names in a child process first: an import that exits or dies ends only the child.

    A module that calls ``sys.exit``, ``os._exit`` or crashes when imported
    would otherwise end ``evaluate`` silently (status 0, no run folder).

    Raises:
        UnknownNameError: The agent cannot be resolved, or importing it ended the process, with how it ended.
    """
    if spec in BUILTINS:
        resolve_agent(spec)
        return
    try:
        done = subprocess.run(
            [sys.executable, "-c", _CHECK, spec, json.dumps(sys.path)], capture_output=True, text=True,
            timeout=AGENT_IMPORT_TIMEOUT, check=False, stdin=subprocess.DEVNULL,
        )  # fmt: skip
    except subprocess.TimeoutExpired:
        raise UnknownNameError(
            f"Expected the agent {spec!r} to import within {AGENT_IMPORT_TIMEOUT:.0f} s; it was still importing. "
            "Does its module run something at import?"
        ) from None
    if done.returncode == 0 and "agent ok" in done.stdout:
        return
    if done.returncode == 2 and done.stderr.strip():
        raise UnknownNameError(done.stderr.strip().splitlines()[-1])
    ended = (
        f"was killed by {signal.Signals(-done.returncode).name}" if done.returncode < 0
        else f"exited with status {done.returncode}"
    )
    raise UnknownNameError(
        f"Expected the agent {spec!r} to define a callable when imported; importing its module {ended} "
        "instead. Remove the exit (sys.exit, os._exit, a KeyboardInterrupt) from its top level, or put it under "
        "if __name__ == '__main__':."
    )


def _load_module(name: str):  # a module
    if not name.endswith(".py"):
        return importlib.import_module(name)
    path = Path(name).expanduser().resolve()
    if not path.is_file():
        raise FileNotFoundError(f"no file {path}")
    key = f"retrokit_agent_{abs(hash(str(path)))}"
    if key in sys.modules:
        return sys.modules[key]
    spec = importlib.util.spec_from_file_location(key, path)
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    sys.modules[key] = module
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module
