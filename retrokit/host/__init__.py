"""The host layer: the native emulator's Python face, the consoles it runs, and the cores it loads.

The lowest layer above the C host (``retrokit.native``); every other layer
drives emulators through it. One module a concern:

- ``primitives``: the only module that imports the native ``_host``.
- ``emulator``: :class:`~retrokit.host.emulator.Emulator`, one console running
  one game, arguments checked; ``runner``: many emulators' frames in one native
  call, on threads (the vector env's engine).
- ``memory``: console addresses over the core's RAM, and a game's fields read
  in one call; ``fields``: :class:`~retrokit.host.fields.FieldSpec`, a named
  RAM field; ``typecodes``: Gym Retro's type codes (``>u2``, ``<i4``, ``>d4``).
- ``systems`` (with ``systems.yaml``): buttons, RAM layout, screen and core
  options per console.
- ``cores``: where each system's libretro core is found (a built one, or the
  wheel's); ``elf``: the check of a core's shared library before it is mapped.
- ``build`` and ``patching``: building a patched core from stable-retro's
  source (``retrokit build-core``, ``docs/cores.md``).
"""

from __future__ import annotations

from retrokit.lazy import lazy_names

__getattr__ = lazy_names(__name__)  # its submodules, on first use: retrokit.host.<module>
