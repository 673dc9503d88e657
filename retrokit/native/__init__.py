"""The C host for libretro cores. Its module ``_host`` is private: use :mod:`retrokit.host.emulator`."""

from __future__ import annotations

from retrokit.lazy import lazy_names

__getattr__ = lazy_names(__name__)  # its submodules, on first use: retrokit.native.<module>
