"""stable-retro's ``env.data``: an env's game fields and scenario, by stable-retro's names, over the env's own.

It is the env's :class:`~retrokit.host.memory.FieldReader` (the fields ``game.yaml`` or
``data.json`` declares, read from the live RAM) and its stepper's scenario run, not a
second copy of them: a value written here is in the RAM the next step reads.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from retrokit.retro.env import RetroEnv

__all__ = ["GameData"]


class GameData:
    """The fields and the scenario of one env (``env.data``).

    Args:
        env: The env.
    """

    def __init__(self, env: RetroEnv) -> None:
        self._env = env

    def lookup_value(self, name: str) -> int:
        """A field's value now.

        Raises:
            FieldNotFoundError: The game has no such field (with the closest names).
        """
        spec = self._env.reader.spec(name)
        return self._env.emulator.peek(spec.address, spec.type)

    def set_value(self, name: str, value: int) -> None:
        """Write a field's value into the RAM.

        Raises:
            FieldNotFoundError: The game has no such field (with the closest names).
        """
        self._env.reader.write(name, int(value))

    def __getitem__(self, name: str) -> int:
        return self.lookup_value(name)

    def __setitem__(self, name: str, value: int) -> None:
        self.set_value(name, value)

    def lookup_all(self) -> dict[str, int]:
        """Every field's value now, by name."""
        return self._env.reader.read()

    def reset(self) -> None:
        """Begin the scenario anew at the console's current state (after ``env.em.set_state``): rewards count from here."""
        self._env.stepper.start()

    def update_ram(self) -> None:
        """Read the fields from the RAM now (stable-retro copies the RAM here; retrokit reads it live, so fields
        already show it: this refreshes the values the last step reported)."""
        self._env.stepper.values = self._env.reader.read()

    def current_reward(self, player: int = 0) -> float:
        """The last step's reward of ``player``."""
        return float(self._env.stepper.rewards[player])

    def is_done(self) -> bool:
        """Whether the scenario ended the episode at the last step."""
        return bool(self._env.stepper.done)

    def __getattr__(self, name: str) -> Any:
        if name in ("memory", "searches", "vars", "valid_actions", "filter_action", "crop_info", "load", "save"):
            raise AttributeError(
                f"retrokit.retro's env.data has no {name} (stable-retro's): use env.get_ram() for the RAM, "
                "env.action_space and env.get_action_meaning(a) for actions, and `retrokit ramsearch` for searches."
            )
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
