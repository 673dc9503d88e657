"""retrokit: emulated console games as reinforcement-learning environments.

The public names, each imported on first use (PEP 562), so that ``import
retrokit`` and ``retrokit --help`` stay fast:

- ``make(game, state, scenario, **options)``: a Gymnasium env
  (:class:`RetroEnv`); ``make_vec``: several stepped together on native
  threads (:class:`ThreadedVectorEnv`); ``State``: where an env starts.
- ``multiplayer``: the PettingZoo envs of two-player games; ``sonic``: the
  Sonic benchmark preset; ``register_envs``: the Gymnasium ids
  (``gymnasium.make("retrokit/Dasher-Genesis-v0")``), registered at import
  (when Gymnasium is imported, if it is not yet).
- ``movie``: ``.bk2`` movies, read, written, recorded and played back.
- ``testing``: ``check_game``, behind ``retrokit validate``.
- ``Emulator``: one console running one game, below the envs.

The package is layered (``docs/architecture.md``), each layer importing only
those below it: ``host`` (the emulator's Python face, over the C host in
``native``), ``data`` (games, their files, states and ROMs), ``dsl`` (the
scenario language), ``envs``, ``movie``, ``ramsearch``, ``testing``,
``benchmark`` (``retrokit evaluate``), this package's public names, and
``commands`` with ``cli`` (the ``retrokit`` command). ``errors`` and ``paths``
serve every layer.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from retrokit.lazy import lazy_names

__version__ = "0.1.0"

# Public name -> the module that defines it (an attribute), or the module itself.
_ATTRIBUTES = {
    "RetroEnv": "retrokit.envs.env",
    "State": "retrokit.envs.env",
    "make": "retrokit.envs.env",
    "ThreadedVectorEnv": "retrokit.envs.vector",
    "make_vec": "retrokit.envs.vector",
    "register_envs": "retrokit.envs.registration",
    "Emulator": "retrokit.host.emulator",
}
_MODULES = {
    "sonic": "retrokit.envs.sonic",
    "multiplayer": "retrokit.envs.multiplayer",
    "movie": "retrokit.movie",
    "testing": "retrokit.testing",
}

__all__ = [
    "Emulator",
    "RetroEnv",
    "State",
    "ThreadedVectorEnv",
    "make",
    "make_vec",
    "movie",
    "multiplayer",
    "register_envs",
    "sonic",
    "testing",
]

if TYPE_CHECKING:
    from retrokit import movie, testing
    from retrokit.envs import multiplayer, sonic
    from retrokit.envs.env import RetroEnv, State, make
    from retrokit.envs.registration import register_envs
    from retrokit.envs.vector import ThreadedVectorEnv, make_vec
    from retrokit.host.emulator import Emulator


__getattr__ = lazy_names(__name__, _ATTRIBUTES, _MODULES)  # and every subpackage: retrokit.envs.sonic.make


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})


def _register() -> None:
    # Gymnasium ids must exist as soon as retrokit is imported, since
    # ``gymnasium.make("retrokit/<Game>-v0")`` is how many users reach us. They
    # are registered when Gymnasium is imported (now, if it is already), so that
    # ``import retrokit`` and every command that needs no env skip its import.
    from retrokit.envs.registration import register_when_gymnasium_loads

    register_when_gymnasium_loads()


_register()
