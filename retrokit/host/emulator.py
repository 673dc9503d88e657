"""The emulator: one console running one game, with arguments checked in Python.

This is the public face of the native host. It finds the system's core,
applies the system's default core options, checks every argument before the
core is touched, and maps console addresses for RAM access.
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import os
import zlib
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Self

import numpy as np

from retrokit.errors import CoreError, InvalidArgumentError, RetrokitError, StateError, UnknownNameError, did_you_mean
from retrokit.host import primitives
from retrokit.host.corecheck import vet_core
from retrokit.host.cores import find_core
from retrokit.host.memory import AddressSpace
from retrokit.host.statelayout import cartridge_class
from retrokit.host.systems import System, get_system, system_for_extension
from retrokit.paths import data_path

logger = logging.getLogger("retrokit.core")
_LOG_LEVELS = (logging.DEBUG, logging.INFO, logging.WARNING, logging.ERROR)


def _log_core(level: int, text: str) -> None:
    logger.log(_LOG_LEVELS[level] if 0 <= level < len(_LOG_LEVELS) else logging.INFO, "%s", text)


class VettedState(bytes):
    """A serialized core state that may be loaded into an emulator: the only kind :meth:`Emulator.set_state` takes.

    Genesis Plus GX trusts a state's contents (a corrupt body kills the process
    with SIGSEGV), so a state reaches a core only as a ``VettedState``. One is
    made in two places only: by :meth:`Emulator.get_state` (the core wrote it,
    in this process), and by the one checker of states in the data layer
    (:mod:`retrokit.data.probe`, through :mod:`retrokit.data.statecheck`), which
    claims the only other way to make one (:func:`claim_mint`) when it is
    imported. It is ``bytes``: it is written, hashed and compared as any state.
    A slice or a copy made with ``bytes(...)`` is plain bytes again, so an
    edited state is never taken as vetted; it pickles as plain bytes too.

    Attributes:
        system: The system whose core the state is for.
    """

    system: str

    def __new__(cls, data: bytes, system: str, *, seal: object = None) -> Self:
        if seal is not _SEAL:
            raise StateError(
                "Expected a state checked by retrokit; found one made directly as VettedState(...). Load a file "
                "with retrokit.data.statecheck.load_state(game, path), or check bytes with "
                "retrokit.data.statecheck.vet_state(data, system, rom)."
            )
        state = super().__new__(cls, data)
        state.system = system
        return state

    def __reduce__(self) -> tuple[type[bytes], tuple[bytes]]:
        return bytes, (bytes(self),)  # what is read back from a pickle is unchecked bytes

    def pack(self) -> PackedState:
        """This state zlib-compressed (fast), to keep many in memory; :meth:`PackedState.unpack` gives it back checked."""
        return PackedState(zlib.compress(self, 1), self.system, seal=_SEAL)


class PackedState:
    """A :class:`VettedState`, compressed (a search keeps thousands); made only by :meth:`VettedState.pack`.

    Attributes:
        system: The system whose core the state is for.
    """

    __slots__ = ("_blob", "system")

    def __init__(self, blob: bytes, system: str, *, seal: object = None) -> None:
        if seal is not _SEAL:
            raise StateError("Expected a state packed by VettedState.pack(); found one made directly as PackedState(...).")
        self._blob, self.system = bytes(blob), system

    def unpack(self) -> VettedState:
        """The state again, as checked as it was when packed."""
        return VettedState(zlib.decompress(self._blob), self.system, seal=_SEAL)

    def __len__(self) -> int:
        return len(self._blob)


_SEAL = object()
_claimed = False


def claim_mint() -> Callable[[bytes, str], VettedState]:
    """Hand the one state checker the only way to make a :class:`VettedState` from bytes; a second claim raises.

    :mod:`retrokit.data.probe` claims it when it is imported, so nothing else
    can: a module that claimed it first would make that import fail, loudly.

    Raises:
        RetrokitError: The mint was claimed already.
    """
    global _claimed
    if _claimed:
        raise RetrokitError(
            "Expected the state checker (retrokit.data.probe) to be the only holder of VettedState's mint; found it "
            "claimed already. Load states through retrokit.data.statecheck instead of claiming the mint."
        )
    _claimed = True
    return lambda data, system: VettedState(data, system, seal=_SEAL)


class Emulator:
    """A console running one game.

    Args:
        system: The system's name (``"Genesis"``) or descriptor.
        rom: The ROM file.
        options: Core options overriding the system's defaults.
        ports: How many controller ports receive input.
        core_path: A core to use instead of the system's.

    Raises:
        CoreNotFoundError: The system's core is not installed.
        CoreError: The core failed to load the ROM.
        UnknownNameError: An option names no option of the core.
    """

    def __init__(
        self,
        system: str | System,
        rom: str | os.PathLike[str],
        *,
        options: Mapping[str, str] | None = None,
        ports: int = 2,
        core_path: str | os.PathLike[str] | None = None,
    ) -> None:
        self.system = get_system(system)
        rom = Path(rom)
        if not rom.is_file():
            raise InvalidArgumentError(f"Expected a ROM file, found nothing at {rom}.")
        if not 1 <= ports <= primitives.MAX_PORTS:
            raise InvalidArgumentError(f"Expected 1 to {primitives.MAX_PORTS} ports, got {ports}.")
        self.ports = ports
        core = Path(core_path) if core_path is not None else find_core(self.system.core)
        vet_core(core, self.system.name, rom)  # a damaged library would make the loader kill the process
        merged = {**self.system.options, **(options or {})}
        system_dir, save_dir = data_path("system"), data_path("saves")  # the core writes there: never through a link
        self._emu = primitives.NativeEmulator(str(core), str(system_dir), str(save_dir), merged, _log_core, ports)
        declared = self._emu.options()
        for key in options or {}:
            if key not in declared:
                self._emu.close()
                raise UnknownNameError(
                    f"Expected an option of the {core.name} core, got {key!r}." + did_you_mean(key, declared)
                )
            allowed = declared[key][2]
            if allowed and options[key] not in allowed:  # type: ignore[index]
                self._emu.close()
                raise InvalidArgumentError(
                    f"Expected one of {', '.join(map(repr, allowed))} for core option {key!r}, got {options[key]!r}."  # type: ignore[index]
                )
        need_path = bool(self._emu.system_info()["need_fullpath"])
        data = None if need_path and not self.system.reload_before_state else rom.read_bytes()
        self._emu.load_game(str(rom), None if need_path else data, self.system.reload_before_state)
        self.rom = rom
        self.space = AddressSpace.for_emulator(self.system, self._emu)
        self._actions = np.zeros(ports, dtype=np.uint16)
        av = self._emu.av_info()
        self._largest = (av["max_height"], av["max_width"])  # the frame the core said it may draw, when it loaded
        # Whether a state load must reload the game (what this ROM's console keeps outside its states would
        # differ), and, where it need not, the console as the first hard reset (a reload) left it.
        self._reload_states = self.system.reload_before_state and self.system.reloads_states(
            hashlib.md5(data or b"", usedforsecurity=False).hexdigest(), cartridge_class(self._emu.serialize())
        )
        self._power_on: bytes | None = None

    @classmethod
    def for_rom(cls, rom: str | os.PathLike[str], **kwargs: object) -> Emulator:
        """Open a ROM on the system its file extension names."""
        return cls(system_for_extension(Path(rom).suffix), rom, **kwargs)  # type: ignore[arg-type]

    # --- running ---------------------------------------------------------------------

    def run(
        self,
        actions: Sequence[int] | np.ndarray | int = 0,
        frames: int = 1,
        screen: np.ndarray | None = None,
        after: int = 0,
    ) -> bool | None:
        """Emulate frames holding one RetroPad button mask per port.

        Args:
            actions: One mask per port (fewer ports than opened press nothing
                on the rest), or a single mask for port 1.
            frames: How many frames to run.
            screen: A ``(H, W, 3)`` uint8 buffer to convert the last frame
                into while it is still in cache, if the shapes match.
            after: Frames of the same step that later calls will run (a
                step run a frame at a time): with ``max_pool``, the frame
                before the step's last is kept wherever it runs.

        Returns:
            With ``screen``, whether the frame was converted into it (its
            shape fitted); else ``None``.
        """
        if type(actions) is not np.ndarray or actions.dtype != np.uint16:  # the exact type is the fast path
            actions = self._as_actions(actions)
        return self._emu.run(actions, frames, screen, after)

    def _as_actions(self, actions: Sequence[int] | np.ndarray | int) -> np.ndarray:
        values = [actions] if isinstance(actions, (int, np.integer)) else list(np.asarray(actions).ravel())
        if len(values) > self.ports:
            raise InvalidArgumentError(f"Expected at most {self.ports} button masks (one per port), got {len(values)}.")
        out = np.zeros(self.ports, dtype=np.uint16)
        for i, v in enumerate(values):
            if not 0 <= int(v) <= 0xFFFF:
                raise InvalidArgumentError(f"Expected button masks from 0 to 0xFFFF, got {v} for port {i + 1}.")
            out[i] = int(v)
        return out

    def set_sticky(self, prob: float, seed: int) -> None:
        """Set the sticky-action probability and seed its random generator.

        On the first frame of each ``run``, with probability ``prob``, the
        buttons of the previous frame are held instead of the new ones.
        """
        if not 0.0 <= float(prob) <= 1.0:
            raise InvalidArgumentError(f"Expected a sticky-action probability in [0, 1], got {prob}.")
        self._emu.set_sticky(float(prob), int(seed) & 0xFFFFFFFFFFFFFFFF)

    def set_video_frames(self, which: str) -> None:
        """Tell the core which frames of each ``run`` anyone will look at.

        The host answers libretro's ``GET_AUDIO_VIDEO_ENABLE`` with it: a core
        that asks (the Genesis Plus GX ``retrokit build-core`` makes) skips
        drawing the others; emulation, and so RAM, is unchanged. With
        ``"last"`` or ``"none"`` audio is reported unwanted unless captured.

        Args:
            which: ``"all"`` (the default), ``"last"`` or ``"none"``.
        """
        modes = {"all": primitives.VIDEO_ALL, "last": primitives.VIDEO_LAST, "none": primitives.VIDEO_NONE}
        if which not in modes:
            raise InvalidArgumentError(
                f"Expected video frames 'all', 'last' or 'none', got {which!r}." + did_you_mean(str(which), modes)
            )
        self._emu.set_video_frames(modes[which])

    @property
    def av_asked(self) -> int:
        """How often the core asked whether video and audio are wanted (0: it never asks, so never skips)."""
        return self._emu.av_asked

    @property
    def av_drawn(self) -> int:
        """How often the core asked whether to draw its frame and was told yes (``av_asked`` counts every ask)."""
        return self._emu.av_drawn

    def set_preprocess(self, spec: tuple[int, ...] | None) -> None:
        """Make observations natively, or (``None``) go back to the RGB screen.

        Args:
            spec: :meth:`retrokit.envs.preprocessing.Preprocessing.native`'s tuple.
                Then :meth:`run`'s ``screen`` and :meth:`observe`'s ``out`` are
                buffers of the preprocessed observation's shape.
        """
        self._emu.set_preprocess(spec)

    def observe(self, out: np.ndarray, *, restart: bool = False, frame: np.ndarray | None = None) -> np.ndarray:
        """Write the preprocessed observation of the last frame (or of an RGB ``frame``) into ``out``.

        Args:
            out: A uint8 buffer of the observation's shape.
            restart: Begin an episode: forget the stacked frames and fill the stack with this one.
            frame: An RGB ``(H, W, 3)`` frame to use instead of the core's last one.
        """
        self._emu.observe(out, restart, frame)
        return out

    def forget_action(self) -> None:
        """Make the next ``run`` apply its buttons from its first frame."""
        self._emu.forget_action()

    @property
    def stuck(self) -> bool:
        """Whether the last ``run``'s first frame kept the previous buttons (a sticky draw)."""
        return self._emu.stuck

    def held(self) -> tuple[int, ...]:
        """The buttons of the last frame run, one mask per port."""
        return self._emu.held()

    def reset(self) -> None:
        """Hard-reset the console, as the reset button would.

        On a system that reloads its game before a state (``reload_before_state``) the game is
        loaded again first, as before a state: what the core keeps outside its states starts afresh.
        For a ROM whose state loads need no reload (:meth:`System.reloads_states`), only the first
        hard reset reloads: the later ones load the state it left (the console's power-on RAM is
        drawn from a generator no state holds, so a console reset alone would start another way).
        """
        if self.system.reload_before_state and not self._reload_states and self._power_on is not None:
            self._load(self._power_on)
            return
        if self.system.reload_before_state:
            self._reload_game()
        self._emu.reset()
        if self.system.reload_before_state and not self._reload_states:
            self._power_on = self._emu.serialize()

    @property
    def reloads_states(self) -> bool:
        """Whether each state load reloads the game first (``reload_before_state``, for this ROM)."""
        return self._reload_states

    @property
    def handle(self) -> primitives.NativeEmulator:
        """The native emulator, for :class:`retrokit.host.runner.Runner`, which runs many in one call."""
        return self._emu

    @property
    def frame(self) -> int:
        """Frames emulated since the emulator was made."""
        return self._emu.frame

    # --- screen, audio, memory ---------------------------------------------------------

    def screen_shape(self) -> tuple[int, int]:
        """Return ``(height, width)`` of the current frame."""
        return self._emu.screen_shape()

    def screen(self, out: np.ndarray | None = None) -> np.ndarray:
        """Return the current frame as an RGB ``uint8`` array of shape (H, W, 3).

        Args:
            out: A buffer of that shape to fill instead of allocating one.

        Raises:
            CoreError: The core drew a frame larger than its system's largest (a corrupt state's
                garbage width, which would ask for terabytes).
        """
        height, width = self._emu.screen_shape()
        av = self._emu.av_info()  # a core may announce a larger one since (SET_SYSTEM_AV_INFO)
        most_h, most_w = max(av["max_height"], self._largest[0]), max(av["max_width"], self._largest[1])
        if not (0 < height <= most_h and 0 < width <= most_w):
            raise CoreError(
                f"Expected a frame of at most {most_w}x{most_h} pixels from the {self.system.name} core; found "
                f"{width}x{height}: the state it runs is corrupt. Load another state, or reset to the game's."
            )
        if out is None:
            out = np.empty((height, width, 3), dtype=np.uint8)
        self._emu.screen(out)
        return out

    def capture_audio(self, enabled: bool = True) -> None:
        """Start (or stop) keeping the audio the core produces."""
        self._emu.capture_audio(bool(enabled))

    def take_audio(self) -> np.ndarray:
        """Return and forget the captured audio, as int16 stereo frames of shape (N, 2)."""
        return np.frombuffer(self._emu.take_audio(), dtype=np.int16).reshape(-1, 2)

    @property
    def ram(self) -> np.ndarray:
        """The system RAM as a writable zero-copy ``uint8`` array, in the core's byte order.

        Where a state load reloads the game (:attr:`reloads_states`), the load frees this
        memory, so :meth:`set_state` refuses while the array lives: copy what you keep.
        """
        view = self._emu.memory(primitives.MEMORY_SYSTEM_RAM)
        if view is None:
            raise InvalidArgumentError(f"The {self.system.name} core exposes no system RAM.")
        return np.frombuffer(view, dtype=np.uint8)

    def retro_ram(self, out: np.ndarray | None = None) -> np.ndarray:
        """A copy of the RAM as stable-retro's ``get_ram()`` gives it: its bytes, in its order and length.

        That is the core's memory map's writable blocks in ascending order of
        address, or its system RAM where it gives no map (``AddressSpace.ram_blocks``):
        on the NES the 2 KiB of internal RAM then the 8 KiB of cartridge RAM at
        0x6000, on a Game Boy video RAM, cartridge RAM, work RAM, OAM and high
        RAM. :attr:`ram` is the system RAM alone.

        Args:
            out: A ``uint8`` array of ``space.ram_size`` bytes to fill instead of allocating one.
        """
        if out is None:
            out = np.empty(self.space.ram_size, dtype=np.uint8)
        return self.space.copy_ram(out)

    def peek(self, address: int, type_code: str = "|u1") -> int:
        """Read a value at a console address, e.g. ``peek(0xFF0366, ">u2")``."""
        return self.space.peek(address, type_code)

    def poke(self, address: int, value: int, type_code: str = "|u1") -> None:
        """Write a value at a console address."""
        self.space.poke(address, value, type_code)

    # --- states and information -------------------------------------------------------------

    def get_state(self) -> VettedState:
        """Serialize the console's state (the core wrote it, so it may be loaded again as it is)."""
        return VettedState(self._emu.serialize(), self.system.name, seal=_SEAL)

    def set_state(self, state: VettedState) -> None:
        """Restore a state made by :meth:`get_state`, or one the state checker passed.

        A ``.state`` file's contents reach this only through the check:
        ``retrokit.data.statecheck.load_state(game, path)`` (or ``vet_state``
        for bytes), which refuses a state that would crash the core.

        Raises:
            StateError: ``state`` was not checked, is for another system, or does not fit this core.
        """
        if not isinstance(state, VettedState):
            found = "None" if state is None else f"{type(state).__name__}"
            raise StateError(
                f"Expected a checked state (from get_state(), or retrokit.data.statecheck.load_state/vet_state) "
                f"to load into the {self.system.name} emulator; found {found}. A state's bytes could crash the "
                "core, so check them first: retrokit.data.statecheck.vet_state(data, system, rom)."
            )
        if state.system != self.system.name:
            raise StateError(
                f"Expected a state for this emulator of {self.system.name}; found one checked for {state.system}. "
                f"Load it into an emulator of {state.system}."
            )
        if self._reload_states:
            self._reload_game()
        self._load(state)

    def _load(self, state: bytes) -> None:
        if self.system.reset_before_state:
            self._emu.reset()
        self._emu.unserialize(state, self.system.state_length == "exact")

    def _reload_game(self) -> None:
        """Unload the game and load it again; :attr:`space` (which every field reader holds) then shows the new memory.

        The core frees the memory it showed, so the space lets go of its views first, and the
        native host refuses while any other view is alive: nothing is left pointing at freed memory.
        """
        try:
            self.space.release()
            self._emu.reload()
        except CoreError:
            with contextlib.suppress(CoreError):  # unless the load itself failed, the game is there: show it again
                self.space.rebind(AddressSpace.for_emulator(self.system, self._emu))
            raise
        self.space.rebind(AddressSpace.for_emulator(self.system, self._emu))

    def av_info(self) -> dict[str, float | int]:
        """Return the frame rate, sample rate and geometry."""
        return self._emu.av_info()

    def options(self) -> dict[str, str]:
        """Return the core options' current values."""
        return {key: value for key, (_, value, _) in self._emu.options().items()}

    def close(self) -> None:
        """Unload the game and the core. Further calls raise."""
        self._emu.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
