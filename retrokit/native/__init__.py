"""The C host for libretro cores. Its module ``_host`` is private: use :mod:`retrokit.host.emulator`."""
