"""The env layer: games as Gymnasium and PettingZoo environments.

- ``env``: :class:`RetroEnv` and ``make``, one game as a Gymnasium env.
- ``stepper``: one episode's steps, shared by the env and the vector env.
- ``vector``: many envs stepped in one native call.
- ``multiplayer``: PettingZoo envs for two-player games.
- ``sonic``: the Sonic benchmark preset.
- ``options``: checking what ``make`` is given; ``compat``: stable-retro's
  conveniences on :class:`RetroEnv`.
- ``actions``, ``buffers``, ``viewer``, ``registration``: action spaces, reusable
  arrays, the ``human`` window, Gymnasium ids.
"""

from __future__ import annotations

from retrokit.lazy import lazy_names

__getattr__ = lazy_names(__name__)  # its submodules, on first use: retrokit.envs.<module>
