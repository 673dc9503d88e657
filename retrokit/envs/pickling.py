"""Envs that pickle as their constructor's arguments, as stable-retro's and Gymnasium's native envs do.

An env holds a native emulator, which cannot be pickled, and which would be
of no use copied into another process anyway. So an env pickles as the
arguments it was made with (``gymnasium.utils.EzPickle``), and unpickling
builds a fresh env from them: the same game, state, scenario and options,
not yet reset. What is *not* carried over: the emulator's current state
(RAM, screen, the frame reached), the episode (its steps, rewards, a movie
being recorded), a state loaded later with ``load_state``, and the seed of the
random generator (seed the copy's ``reset``). This is what Gymnasium's
``AsyncVectorEnv`` and SuperSuit's ``concat_vec_envs_v1(..., num_cpus=2)``
need: they send envs (or the functions that make them) to worker processes.
"""

from __future__ import annotations

from typing import Any

from gymnasium.utils import EzPickle


class PicklesAsArguments(EzPickle):
    """Mixed into an env: pickles as its constructor's arguments, and unpickles into a fresh env made from them.

    The class calls ``PicklesAsArguments.__init__(self, *args, **kwargs)`` with
    the arguments it was given, as they were given (every one must pickle).
    Unlike ``EzPickle``, unpickling runs ``__init__`` on the object itself
    rather than on a temporary one whose state is then copied: an env owns an
    emulator and threads, which a discarded twin would have to close.
    """

    def __setstate__(self, state: dict[str, Any]) -> None:
        type(self).__init__(self, *state["_ezpickle_args"], **state["_ezpickle_kwargs"])
