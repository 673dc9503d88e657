"""stable-retro's conveniences on :class:`~retrokit.envs.env.RetroEnv`, for code being ported.

stable-retro's ``RetroEnv`` has ``buttons``, ``get_action_meaning``,
``get_ram`` and ``load_state``; code moving to retrokit reaches for them
(``docs/from-stable-retro.md`` maps the rest). They behave as stable-retro's
do, on retrokit's own objects: the button names include ``None`` for unused
RetroPad ids, an action's meaning is the buttons the console really sees
(after the ``filtered`` action type's filter), and a loaded state is where the
next ``reset()`` starts.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np


class StableRetroCompat:
    """Mixed into RetroEnv: stable-retro's ``buttons``, ``get_action_meaning``, ``get_ram``, ``load_state``."""

    @property
    def buttons(self) -> list[str | None]:
        """Each RetroPad id's button name for this console, ``None`` where unused (stable-retro's order)."""
        return list(self.emulator.system.buttons)  # type: ignore[attr-defined]

    def get_action_meaning(self, action: Any) -> list[str | None] | list[list[str | None]]:
        """The names of the buttons an action presses: one list, or one per player with several players."""
        buttons = self.buttons
        masks = self.actions.to_masks(action)  # type: ignore[attr-defined]
        meanings = [[name for i, name in enumerate(buttons) if mask >> i & 1] for mask in masks]
        return meanings[0] if len(meanings) == 1 else meanings

    def get_ram(self) -> np.ndarray:
        """A copy of the RAM (``uint8``) as stable-retro's ``get_ram`` gives it: the same bytes, order and length.

        See :meth:`retrokit.host.emulator.Emulator.retro_ram` (on the NES, 10,240 bytes: the 2 KiB of
        internal RAM, then the cartridge RAM at 0x6000).
        """
        return self.emulator.retro_ram()  # type: ignore[attr-defined]

    def load_state(self, state: str | os.PathLike[str]) -> None:
        """Start the next episodes at another state: a name of this game's states, or a ``.state`` path.

        As in stable-retro, this takes effect at the next ``reset()``.

        Raises:
            StateNotFoundError: The game has no state of that name.
        """
        from retrokit.data.resolve import resolve_state

        start = resolve_state(self.game, state, players=self.players)  # type: ignore[attr-defined]
        self._starts, self._start_odds = [start], None  # no more drawing among weighted states
        self._use_start(start)  # type: ignore[attr-defined]
