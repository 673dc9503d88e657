"""stable-retro's ``RetroEmulator``: a console run a frame at a time, as ``env.em`` and on its own.

States go in only through retrokit's checked load: bytes a core wrote in this process
(:meth:`get_state`) load as they are, and any other bytes are checked first
(:func:`retrokit.data.statecheck.check_state` for an env's game, ``vet_state`` for a bare ROM),
so a state that would crash the core is refused with a :class:`~retrokit.errors.StateError`
instead of killing the process.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from retrokit.data.games import Game
from retrokit.data.statecheck import check_state, vet_state
from retrokit.errors import InvalidArgumentError
from retrokit.host.emulator import Emulator, VettedState

__all__ = ["EmulatorFace", "RetroEmulator"]


class EmulatorFace:
    """stable-retro's emulator calls over a retrokit :class:`~retrokit.host.emulator.Emulator`.

    Args:
        emulator: The console.
        game: The game it runs, whose states a foreign state is checked against; ``None`` for a bare ROM.
    """

    def __init__(self, emulator: Emulator, game: Game | None = None) -> None:
        self.emulator, self.game = emulator, game
        self._masks = np.zeros(emulator.ports, dtype=np.uint16)
        self._audio = False

    def checked(self, state: bytes, source: str) -> VettedState:
        """``state`` ready to load: as it is if a core of this system wrote it here, else through the checked load.

        Raises:
            StateError: The state is another game's, or would crash or hang the core.
        """
        if isinstance(state, VettedState) and state.system == self.emulator.system.name:
            return state
        data = bytes(state)
        if self.game is not None:
            return check_state(self.game, data, source=source, rom=self.emulator.rom)
        return vet_state(data, self.emulator.system, self.emulator.rom, source=source)

    def get_state(self) -> bytes:
        """The console's state, serialized (bytes)."""
        return self.emulator.get_state()

    def set_state(self, state: bytes) -> bool:
        """Load a state: one :meth:`get_state` gave, a ``.state`` file's bytes (ungzipped) or a movie's.

        Raises:
            StateError: The state is another game's, or would crash or hang the core.
        """
        self.emulator.set_state(self.checked(state, "the state given to em.set_state()"))
        return True

    def set_button_mask(self, mask: Sequence[int] | np.ndarray, player: int = 0) -> None:
        """Hold these buttons from the next :meth:`step` on: one 0 or 1 per button, in ``env.buttons``' order.

        Raises:
            InvalidArgumentError: No such player port, or more than 16 buttons.
        """
        if not 0 <= player < self.emulator.ports:
            raise InvalidArgumentError(
                f"Expected a player from 0 to {self.emulator.ports - 1} for set_button_mask; got {player}. "
                "Make the env with players=2 to press a second player's buttons."
            )
        bits = np.asarray(mask).ravel()
        if bits.size > 16:
            raise InvalidArgumentError(f"Expected at most 16 buttons in a button mask; got {bits.size}.")
        self._masks[player] = sum(1 << i for i, pressed in enumerate(bits) if pressed)

    def step(self) -> None:
        """Emulate one frame with the buttons :meth:`set_button_mask` set."""
        self.emulator.run(self._masks, 1)

    def get_screen(self) -> np.ndarray:
        """The last frame, RGB ``uint8`` of shape (height, width, 3)."""
        return self.emulator.screen()

    def get_resolution(self) -> tuple[int, int]:
        """The screen's (width, height)."""
        height, width = self.emulator.screen_shape()
        return width, height

    def get_screen_rate(self) -> float:
        """Frames per second."""
        return float(self.emulator.av_info()["fps"])

    def get_audio_rate(self) -> float:
        """Audio samples per second."""
        return float(self.emulator.av_info()["sample_rate"])

    def get_audio(self) -> np.ndarray:
        """The audio since the last call, int16 stereo of shape (N, 2); the first call starts keeping it (empty)."""
        if not self._audio:
            self.emulator.capture_audio(True)
            self._audio = True
        return self.emulator.take_audio()

    def get_rotation(self) -> int:
        """The screen's rotation in quarter turns: retrokit's cores draw upright (0)."""
        return 0

    def __getattr__(self, name: str) -> Any:
        if name in ("add_cheat", "clear_cheats", "configure_data"):
            raise AttributeError(
                f"retrokit.retro's emulator has no {name} (stable-retro's): "
                + ("retrokit has no cheats; write RAM with env.data.set_value(name, value)." if "cheat" in name
                   else "an env reads its game's fields itself: use env.data.")
            )  # fmt: skip
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")


class RetroEmulator(EmulatorFace):
    """stable-retro's ``RetroEmulator(rom_path)``: a ROM on the system its extension names, with no game data.

    Raises:
        UnsupportedSystemError: No system has that extension.
        CoreNotFoundError: The system's core is not installed.
    """

    def __init__(self, rom_path: str | os.PathLike[str]) -> None:
        super().__init__(Emulator.for_rom(rom_path))
        self.step()  # stable-retro's emulator runs one frame as it loads the game (its screen exists from then on)

    def close(self) -> None:
        """Unload the game and the core."""
        self.emulator.close()
