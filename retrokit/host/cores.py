"""Finding libretro cores on disk.

Cores are searched, in order, in the folders of ``RETROKIT_CORES`` (separated
by ``os.pathsep``), the stable-retro wheel's ``cores/`` folder, and Debian's
libretro folders.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from retrokit.errors import CoreNotFoundError
from retrokit.paths import wheel_cores_dir

_DEBIAN_DIRS = ("/usr/lib/x86_64-linux-gnu/libretro", "/usr/lib/aarch64-linux-gnu/libretro", "/usr/lib/libretro")


def core_dirs() -> list[Path]:
    """Return the folders searched for cores, in order."""
    dirs = [Path(p) for p in os.environ.get("RETROKIT_CORES", "").split(os.pathsep) if p]
    wheel = wheel_cores_dir()
    if wheel is not None:
        dirs.append(wheel)
    dirs.extend(Path(d) for d in _DEBIAN_DIRS)
    return dirs


def core_filename(core: str) -> str:
    """Return a core's shared-library file name on this platform."""
    suffix = ".dylib" if sys.platform == "darwin" else ".dll" if sys.platform == "win32" else ".so"
    return f"{core}_libretro{suffix}"


def find_core(core: str) -> Path:
    """Return the path of a core's shared library, such as ``genesis_plus_gx``.

    Raises:
        CoreNotFoundError: No search folder holds the core.
    """
    name = core_filename(core)
    searched = core_dirs()
    for folder in searched:
        candidate = folder / name
        if candidate.is_file():
            return candidate
    raise CoreNotFoundError(
        f"Expected the libretro core {name} in one of: {', '.join(str(d) for d in searched)}; found it in none. "
        f"Install the stable-retro wheel (pip install 'stable-retro>=1.0,<2'), or put the core in a folder "
        f"and name that folder in RETROKIT_CORES."
    )
