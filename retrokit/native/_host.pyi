"""Private native host for libretro cores. Use :class:`retrokit.host.emulator.Emulator`.

Every function here is a data-only primitive: it loads, runs, copies or
converts. Arguments are checked before the core is touched, and a failing core
call raises :class:`retrokit.errors.CoreError` (or a subclass); nothing aborts.
"""

from collections.abc import Callable, Sequence
from typing import Any, overload

import numpy as np
import numpy.typing as npt

MEMORY_SYSTEM_RAM: int
MAX_PORTS: int
PLAN_COLUMNS: int
VIDEO_ALL: int
VIDEO_LAST: int
VIDEO_NONE: int

class Emulator:
    """One libretro core, privately loaded, with at most one game."""

    def __init__(
        self,
        core_path: str,
        system_dir: str,
        save_dir: str,
        options: dict[str, str] | None = None,
        log: Callable[[int, str], None] | None = None,
        ports: int = 2,
    ) -> None: ...
    def load_game(self, path: str, data: bytes | None = None, keep: bool = False) -> None:
        """Load a game (its bytes, unless the core needs its path); ``keep`` holds a copy for :meth:`reload`."""
    def system_info(self) -> dict[str, object]: ...
    def av_info(self) -> dict[str, float | int]: ...
    def options(self) -> dict[str, tuple[str, str, tuple[str, ...]]]:
        """Map each core option key to (description, current value, allowed values)."""
    def set_sticky(self, prob: float, seed: int) -> None: ...
    def set_video_frames(self, mode: int) -> None:
        """Which frames of each ``run`` the core is told to draw (``VIDEO_ALL``, ``VIDEO_LAST``, ``VIDEO_NONE``).

        Also: audio is wanted with ``VIDEO_ALL`` or while captured, else not.
        """
    @property
    def av_asked(self) -> int:
        """How often the core asked whether video and audio are wanted (GET_AUDIO_VIDEO_ENABLE)."""
    @property
    def av_drawn(self) -> int:
        """How often the core asked and was told to draw the frame (video wanted)."""
    def set_preprocess(self, spec: tuple[int, ...] | None) -> None:
        """Make observations through the native preprocessing, or (``None``) as the RGB screen.

        ``spec`` is ``(screen_height, screen_width, top, bottom, left, right, height, width, method, gray,
        max_pool, stack, channels_first)`` (``rk_prep_spec``; method 0 none, 1 area, 2 bilinear, 3 nearest).
        Then ``run``'s screen (and a Runner's) is a uint8 buffer of the observation's size, and a run keeps
        its next-to-last frame for the max-pool (and tells the core both are seen).
        """
    def observe(
        self, out: npt.NDArray[np.uint8], restart: bool = False, frame: npt.NDArray[np.uint8] | None = None
    ) -> None:
        """Write the preprocessed observation of the last frame (or of the RGB ``frame``) into ``out``.

        ``restart`` begins an episode: the stack is filled with this frame and any kept frame forgotten.
        """
    def forget_action(self) -> None:
        """Make the next ``run`` apply its action from the first frame, as after a reset."""
    def run(
        self,
        actions: npt.NDArray[np.uint16],
        frames: int,
        screen: npt.NDArray[np.uint8] | None = None,
        after: int = 0,
    ) -> bool | None:
        """Run frames (``after`` more of the step follow in later calls); with ``screen``, convert the last
        frame into it and return whether it fitted."""
    def screen_shape(self) -> tuple[int, int]: ...
    def screen(self, out: npt.NDArray[np.uint8]) -> None: ...
    def memory(self, kind: int) -> memoryview | None: ...
    def memory_maps(self) -> list[dict[str, object]]: ...
    def memory_span(self, first: int, count: int) -> memoryview | None:
        """One view over descriptors ``first`` to ``first + count - 1`` of :meth:`memory_maps`, when each one's console
        addresses and memory begin where the one before ends; ``None`` where they do not."""
    def serialize(self) -> bytes: ...
    def unserialize(self, data: bytes, exact: bool = True) -> None: ...
    def reload(self) -> None:
        """Unload the game and load its kept copy again (``load_game(..., keep=True)``).

        The core's memory moves: every view from :meth:`memory` and :meth:`memory_maps` must be released
        before (else :class:`retrokit.errors.CoreError`, and nothing happens), and made again after.
        """
    def reset(self) -> None: ...
    def capture_audio(self, enabled: bool) -> None: ...
    def take_audio(self) -> bytes:
        """Return and clear the captured audio: interleaved int16 stereo samples."""
    @property
    def frame(self) -> int: ...
    @property
    def stuck(self) -> bool:
        """Whether the last ``run``'s first frame kept the previous buttons."""
    def held(self) -> tuple[int, ...]:
        """The buttons of the last frame run, one mask per port (zeros after a reset)."""
    def close(self) -> None: ...

class Runner:
    """A pool of native worker threads that, with the calling thread, run several emulators' frames in one call."""

    def __init__(self, threads: int) -> None:
        """Start ``threads`` workers (0 runs everything on the calling thread)."""
    @property
    def moved(self) -> int:
        """How many times a waiting caller moved a worker that lost its CPU (to another process) onto its own."""
    def run(
        self,
        emulators: Sequence[Emulator],
        actions: npt.NDArray[np.uint16],
        frames: int,
        screens: Sequence[npt.NDArray[np.uint8]] | None = None,
        after: int = 0,
    ) -> tuple[bool, ...]:
        """Run every emulator's frames, the GIL released, on the calling thread and the workers.

        Any number of emulators: the threads take them one at a time until
        none is left. ``actions`` has one row of port masks per emulator. Each
        screen is converted into its buffer when its shape fits the frame (or,
        for an emulator with a preprocessing, its observation is made into it:
        always); the result says, per emulator, whether it was. ``after`` is
        as :meth:`Emulator.run`'s.
        """

def pack_buttons(
    action: npt.NDArray[Any], buttons: int, out: npt.NDArray[np.uint16], table: npt.NDArray[np.uint16] | None = None
) -> bool:
    """Pack a button array, ``buttons`` items per player, into one mask per player in ``out``.

    An item of 1 presses its button, 0 releases it. With ``table``
    (``2**buttons`` masks), each player's mask is replaced by its entry there.
    Returns False, writing nothing, when the array's item format is not a
    number or an item is neither 0 nor 1 (the caller refuses it, saying which).
    """

@overload
def read_fields(
    buffers: Sequence[memoryview | bytes | bytearray | npt.NDArray[np.uint8]],
    plan: npt.NDArray[np.int64],
    out: npt.NDArray[np.int64],
    names: None = None,
) -> None: ...
@overload
def read_fields(
    buffers: Sequence[memoryview | bytes | bytearray | npt.NDArray[np.uint8]],
    plan: npt.NDArray[np.int64],
    out: npt.NDArray[np.int64],
    names: tuple[str, ...],
) -> dict[str, int]: ...
def read_fields(
    buffers: Sequence[memoryview | bytes | bytearray | npt.NDArray[np.uint8]],
    plan: npt.NDArray[np.int64],
    out: npt.NDArray[np.int64],
    names: tuple[str, ...] | None = None,
) -> dict[str, int] | None:
    """Decode every field of a plan from RAM buffers into ``out``; with ``names``, also return them by name.

    In the dict, an 8-byte unsigned field keeps its true value (``out`` holds
    its two's complement).

    ``plan`` has one row per field: ``[buffer, width, kind, mask, off0 .. off7]``
    with offsets from least to most significant byte, and ``kind`` 0 unsigned,
    1 signed, 2 BCD, 3 low-nibble BCD.
    """
