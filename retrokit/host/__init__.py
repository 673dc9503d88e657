"""The host layer: the native emulator's Python face, and what describes a console.

- ``primitives``: the only module that imports the native ``_host``.
- ``emulator``: :class:`Emulator`, one console running one game, arguments checked.
- ``memory``: console addresses over the core's RAM, and a game's fields read in one call.
- ``fields``: :class:`FieldSpec`, a named RAM field (plain data).
- ``typecodes``: Gym Retro's type codes (``>u2``, ``<i4``, ``>d4``...).
- ``systems`` (with ``systems.yaml``): buttons, RAM layout and core options per console.
- ``cores``: where each system's libretro core is found.
"""

from __future__ import annotations

from retrokit.lazy import lazy_names

__getattr__ = lazy_names(__name__)  # its submodules, on first use: retrokit.host.<module>
