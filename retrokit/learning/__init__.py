"""Learning agents: PPO (and the others the paper ran) built in, trained and evaluated by retrokit.

A layer above :mod:`retrokit.benchmark` and :mod:`retrokit.envs`:

- :mod:`.algorithms` names each algorithm's module and the table of its config's keys (:class:`~.algorithms.Key`);
- :mod:`.config` loads an agent's config, a shipped one by name (``configs/<agent>/<name>.yaml``) or a user's file;
- :mod:`.task` turns a benchmark's env into what a learner sees: the ``learning:`` block's actions, the max-x
  reward and the reward scale (from the Sonic preset's pieces), and the native observation options;
- :mod:`.policy` is the saved-policy format (``policy.json`` beside the library's weights) and its checked load;
- :mod:`.setup` prepares a learning agent for ``retrokit evaluate`` (config, ``--init``, zero-shot);
- :mod:`.play` is the agent ``retrokit evaluate --agent ppo`` calls on each level;
- :mod:`.trainrun` is ``retrokit train``'s run folder: settings, lock, checkpoints, the learning curve;
- :mod:`.ppo` is PPO over Stable-Baselines3;
- :mod:`.rainbow` is Rainbow over Tianshou.

The libraries are the extra ``retrokit-rl[train]`` (stable-baselines3, torch); nothing here imports them until
an agent plays or trains.
"""

from __future__ import annotations

from retrokit.lazy import lazy_names

__getattr__ = lazy_names(__name__)  # its submodules, on first use: retrokit.learning.<module>

#: Seconds between ``retrokit train``'s checkpoints, its ``--checkpoint-every`` default: kept here, where the
#: command's parser reads it without importing the training stack (``retrokit --help`` stays light).
DEFAULT_CHECKPOINT_SECONDS = 600.0
