"""The native host's primitives: the one module that imports ``retrokit.native._host``.

Everything the Python side takes from C comes through here, so the boundary
is one file to read: a privately loaded core (:data:`NativeEmulator`), the
thread pool that runs many of them at once (:data:`NativeRunner`), and two
array-in, array-out helpers for the hot path of a step. They are data-only:
load, run frames, copy RAM or the screen into a caller's buffer, serialize.
Game logic stays in Python; the checked API is :class:`retrokit.host.Emulator`.
Their signatures are in ``retrokit/native/_host.pyi``.
"""

from __future__ import annotations

from retrokit.native import _host

NativeEmulator = _host.Emulator
NativeRunner = _host.Runner

#: Pack a button array into one RetroPad mask per player (``_host.pyi``).
pack_buttons = _host.pack_buttons
#: Decode every field of a plan from RAM buffers in one call (``_host.pyi``).
read_fields = _host.read_fields

MAX_PORTS: int = _host.MAX_PORTS
PLAN_COLUMNS: int = _host.PLAN_COLUMNS
MEMORY_SYSTEM_RAM: int = _host.MEMORY_SYSTEM_RAM
# Which frames of a run the core is told are seen (GET_AUDIO_VIDEO_ENABLE; docs/cores.md).
VIDEO_ALL: int = _host.VIDEO_ALL
VIDEO_LAST: int = _host.VIDEO_LAST
VIDEO_NONE: int = _host.VIDEO_NONE
