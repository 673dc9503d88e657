"""The env layer: games as Gymnasium and PettingZoo environments, and the window to play them by hand.

On the host, data and scenario layers; the movie, testing, benchmark and
command layers build on it. One module a concern:

- ``env``: :class:`~retrokit.envs.env.RetroEnv` and ``make``, one game as a
  Gymnasium env; ``options``: checking every keyword ``make`` takes before
  anything is built; ``compat``: stable-retro's conveniences, for ported code.
- ``stepper``: one episode's steps (buttons, frames, fields, scenario), shared
  by the env and the vector env, with observers (movie recording).
- ``vector``: many envs stepped in one native call (``make_vec``).
- ``multiplayer``: PettingZoo parallel and AEC envs for two-player games.
- ``sonic``: the Sonic benchmark preset; ``registration``: the Gymnasium ids
  of every game and Sonic level.
- ``actions``: action spaces to button masks; ``buffers``: reusable
  observation arrays; ``viewer``: the ``human`` render window.
- ``play``: ``retrokit play``, a game played by hand, saving states and
  recording movies.
"""

from __future__ import annotations

from retrokit.lazy import lazy_names

__getattr__ = lazy_names(__name__)  # its submodules, on first use: retrokit.envs.<module>
