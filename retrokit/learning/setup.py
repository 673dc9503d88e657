"""A learning agent made ready for ``retrokit evaluate``: its config, its start policy, and learn or not.

``retrokit evaluate --agent ppo [--agent-config NAME|FILE] [--init PATH] [--no-learn]``
prepares a :class:`LearnerSetup` once, in the main process, before any level
starts: the config checked, the start policy's ``policy.json`` read and checked
against the benchmark's task and the config's observation, the library found.
Each level's task carries it to its worker, where :mod:`.play` hands it to
the algorithm; ``run.json`` records :meth:`LearnerSetup.settings`, so
``--resume`` refuses a changed config or start policy.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

from retrokit.benchmark.definition import Benchmark, LearningTask
from retrokit.benchmark.paper import paper_name
from retrokit.errors import InvalidArgumentError, PolicyFileError
from retrokit.learning.algorithms import ALGORITHMS, algorithm, is_learning_agent
from retrokit.learning.config import AgentConfig, load_config
from retrokit.learning.policy import SavedPolicy, read_policy
from retrokit.learning.task import learning_task


@dataclass(frozen=True)
class LearnerSetup:
    """What a learning agent needs on each level.

    Attributes:
        agent: The agent (``ppo``).
        config: Its checked config.
        task: The benchmark's actions and x.
        observation: The native preprocessing options the runner adds to each level's env.
        init: The start policy's ``policy.json`` (``--init``), or ``None`` to start from scratch.
        init_sha256: The start policy's weights' digest.
        learn: Learn during the budget (``False``: play the start policy as it is, the zero-shot score).
    """

    agent: str
    config: AgentConfig
    task: LearningTask
    observation: dict[str, Any] = field(default_factory=dict)
    init: str | None = None
    init_sha256: str | None = None
    learn: bool = True

    @property
    def paper_agent(self) -> str | None:
        """The paper's name for this play of the agent: ``PPO`` from scratch, ``Joint PPO`` from a trained policy
        (the reports set it beside that row); ``None`` for a zero-shot play, which the paper's tables lack."""
        return paper_name(self.agent, self.init) if self.learn else None

    def settings(self) -> dict[str, Any]:
        """What determines the agent's play, for ``run.json`` (``--resume`` requires the same)."""
        return {
            "paper_agent": self.paper_agent,
            "config": self.config.as_dict(),
            "task": self.task.as_dict(),
            "init": None if self.init is None else {"policy": self.init, "weights_sha256": self.init_sha256},
            "learn": self.learn,
        }

    def start_policy(self) -> SavedPolicy | None:
        """The start policy, read again in the worker (and checked to be the one prepared)."""
        if self.init is None:
            return None
        policy = read_policy(self.init, self.agent)
        if policy.sha256 != self.init_sha256:
            raise PolicyFileError(
                f"Expected the start policy {self.init} to be the one the run began with, but its weights changed "
                "meanwhile; start a new run."
            )
        return policy


def prepare(
    agent: str,
    benchmark: Benchmark,
    config: str | os.PathLike[str] | None = None,
    init: str | os.PathLike[str] | None = None,
    *,
    learn: bool = True,
) -> LearnerSetup | None:
    """Prepare ``agent`` for an evaluation of ``benchmark``; ``None`` if it is no learning agent.

    Raises:
        InvalidArgumentError: ``--agent-config``, ``--init`` or ``--no-learn`` given to an agent that is not a
            learning one; ``--no-learn`` without ``--init``; the benchmark says nothing of its task.
        AgentConfigError: The config is wrong.
        PolicyFileError: The start policy is missing, damaged, of another agent, or does not fit the task or
            the config's observation.
        MissingExtraError: The agent's library is not installed.
    """
    if not is_learning_agent(agent):
        given = [name for name, value in (("--agent-config", config), ("--init", init)) if value is not None]
        if not learn:
            given.append("--no-learn")
        if given:
            raise InvalidArgumentError(
                f"Expected {' and '.join(given)} with a learning agent ({', '.join(ALGORITHMS)}), got them with "
                f"--agent {agent}; drop them, or use --agent ppo."
            )
        return None
    if not learn and init is None:
        raise InvalidArgumentError(
            "Expected --init PATH with --no-learn: zero-shot play needs a trained policy (`retrokit train`)."
        )
    module = algorithm(agent)
    checked = load_config(agent, config)
    task = learning_task(benchmark)
    observation = module.observation_options(checked.values)
    policy = None if init is None else read_policy(init, agent)
    if policy is not None:
        check_fits(policy, task, observation)
    module.require()
    return LearnerSetup(
        agent, checked, task, observation,
        None if policy is None else str(policy.path.resolve()), None if policy is None else policy.sha256, learn,
    )  # fmt: skip


def check_fits(policy: SavedPolicy, task: LearningTask, observation: dict[str, Any]) -> None:
    """Refuse a start policy whose actions or observation differ from this run's.

    Raises:
        PolicyFileError: They differ; the message says how.
    """
    theirs = [list(combo) for combo in policy.meta["actions"]]
    ours = [list(combo) for combo in task.actions]
    if theirs != ours:
        raise PolicyFileError(
            f"Expected the policy {policy.path} to choose among this benchmark's actions {ours}, but it was "
            f"trained on {theirs}; train it on a benchmark with the same learning.actions."
        )
    saved = policy.meta["observation"]["options"]
    if saved != {key: list(value) if isinstance(value, tuple) else value for key, value in observation.items()}:
        raise PolicyFileError(
            f"Expected the policy {policy.path} to see the observation this config makes ({observation}), but "
            f"it was trained on {saved}; use its config (--agent-config with the same frame_size, frame_stack "
            "and grayscale)."
        )
