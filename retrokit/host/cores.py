"""Finding libretro cores on disk.

Cores are searched, in order, in:

1. the folders of ``RETROKIT_CORES`` (separated by ``os.pathsep``),
2. the cores built by ``retrokit build-core`` in the data folder
   (``<data>/cores``), each used only while it was built from the installed
   stable-retro version (its save states must fit the wheel's),
3. the stable-retro wheel's ``cores/`` folder,
4. Debian's libretro folders.
"""

from __future__ import annotations

import functools
import importlib.metadata
import json
import os
import sys
from dataclasses import dataclass
from pathlib import Path

from retrokit.errors import CoreNotFoundError, FileSystemError
from retrokit.paths import data_path, read_regular_file, wheel_cores_dir

CORES_ENV = "RETROKIT_CORES"
_DEBIAN_DIRS = ("/usr/lib/x86_64-linux-gnu/libretro", "/usr/lib/aarch64-linux-gnu/libretro", "/usr/lib/libretro")


@dataclass(frozen=True)
class FoundCore:
    """A core's shared library and where it came from.

    Attributes:
        path: The shared library.
        origin: ``"RETROKIT_CORES"``, ``"built"``, ``"wheel"`` or ``"system"``.
        note: A short remark for listings (a built core's patch and source version).
    """

    path: Path
    origin: str
    note: str = ""


def core_filename(core: str) -> str:
    """Return a core's shared-library file name on this platform."""
    suffix = ".dylib" if sys.platform == "darwin" else ".dll" if sys.platform == "win32" else ".so"
    return f"{core}_libretro{suffix}"


@functools.cache  # asked at every make(); reading the package's metadata took ~3 ms, and it is fixed for a process
def stable_retro_version() -> str | None:
    """Return the installed stable-retro version, or ``None``."""
    try:
        return importlib.metadata.version("stable-retro")
    except importlib.metadata.PackageNotFoundError:
        return None


def built_cores_dir(data: Path | str | None = None) -> Path:
    """Return where ``retrokit build-core`` installs cores: ``<data>/cores``, never a link (its records vouch).

    Raises:
        PlantedLinkError: It is a symlink (:func:`retrokit.paths.data_path`).
    """
    return data_path("cores", data=data)


def build_record_path(core: str, data: Path | str | None = None) -> Path:
    """Return the file that describes a built core: ``<data>/cores/<core>.build.json``."""
    return built_cores_dir(data) / f"{core}.build.json"


def read_build_record(core: str, data: Path | str | None = None) -> dict[str, str] | None:
    """Return what ``retrokit build-core`` recorded about a built core, or ``None`` if nothing readable."""
    try:  # a record vouches for a core's bytes: never read through a link, nor more than a record holds
        text = read_regular_file(build_record_path(core, data), "a core's build record", 1 << 16, follow=False)
        record = json.loads(text.decode("utf-8"))
    except (FileSystemError, ValueError):
        return None
    return record if isinstance(record, dict) else None


def built_core(core: str, data: Path | str | None = None) -> FoundCore | None:
    """Return the core ``retrokit build-core`` made, if it exists and fits the installed stable-retro."""
    path = built_cores_dir(data) / core_filename(core)
    record = read_build_record(core, data)
    if not path.is_file() or record is None or record.get("stable_retro") != stable_retro_version():
        return None
    return FoundCore(path, "built", f"{record.get('patch', 'unpatched')}, from stable-retro {record['stable_retro']}")


def locate_core(core: str) -> FoundCore:
    """Return a core's shared library and where it was found, searching in the order above.

    Raises:
        CoreNotFoundError: No search folder holds the core.
    """
    name = core_filename(core)
    searched = [Path(p) for p in os.environ.get(CORES_ENV, "").split(os.pathsep) if p]
    for folder in searched:
        if (folder / name).is_file():
            return FoundCore(folder / name, CORES_ENV)
    built = built_core(core)
    if built is not None:
        return built
    searched.append(built_cores_dir())
    wheel = wheel_cores_dir()
    others = [(wheel, "wheel")] if wheel is not None else []
    others += [(Path(d), "system") for d in _DEBIAN_DIRS]
    for folder, origin in others:
        if (folder / name).is_file():
            return FoundCore(folder / name, origin)
        searched.append(folder)
    raise CoreNotFoundError(
        f"Expected the libretro core {name} in one of: {', '.join(str(d) for d in searched)}; found it in none. "
        f"Install the stable-retro wheel (pip install 'stable-retro>=1.0,<2'), or put the core in a folder "
        f"and name that folder in {CORES_ENV}."
    )


def find_core(core: str) -> Path:
    """Return the path of a core's shared library, such as ``genesis_plus_gx``.

    Raises:
        CoreNotFoundError: No search folder holds the core.
    """
    return locate_core(core).path


def wheel_core(core: str) -> Path | None:
    """Return the stable-retro wheel's own build of a core, or ``None`` (to compare a built core with)."""
    folder = wheel_cores_dir()
    path = folder / core_filename(core) if folder is not None else None
    return path if path is not None and path.is_file() else None
