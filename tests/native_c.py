"""The native host's plain C, compiled on its own for the tests, and called through ctypes.

The pixel conversion and the cores' private ``rand()`` are plain C with no
Python in them (``retrokit/native/video.c``, ``isolate.c``). Rather than ship
test-only functions in the extension, the tests build those files into a
small shared library of their own and check them directly.
"""

from __future__ import annotations

import ctypes
import re
import shutil
import subprocess
from pathlib import Path

NATIVE = Path(__file__).resolve().parent.parent / "retrokit" / "native"
RAND_DEGREE = 31
#: libretro's pixel formats by name, as the header the C is built with declares them.
PIXEL_FORMATS = {
    name: int(value)
    for name, value in re.findall(r"#define RK_RETRO_PIXEL_FORMAT_(\w+) (\d+)", (NATIVE / "libretro_api.h").read_text())
}


class Rand(ctypes.Structure):
    """``rk_rand`` of ``core.h``: glibc's TYPE_3 random() state."""

    _fields_ = [("state", ctypes.c_int32 * RAND_DEGREE), ("front", ctypes.c_int), ("rear", ctypes.c_int)]


def build(folder: Path) -> ctypes.CDLL | None:
    """Compile video.c and isolate.c into ``folder``; ``None`` when no C compiler is installed."""
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        return None
    library = folder / "retrokit_native_c.so"
    # isolate.c's rand() replacements find their emulator through core.c's rk_current.
    current = folder / "current.c"
    current.write_text('#include "callbacks.h"\n_Thread_local rk_core *rk_current;\n')
    sources = [str(NATIVE / "video.c"), str(NATIVE / "isolate.c"), str(current)]
    subprocess.run(
        [cc, "-shared", "-fPIC", "-O2", "-std=c11", f"-I{NATIVE}", *sources, "-o", str(library), "-ldl"], check=True
    )
    lib = ctypes.CDLL(str(library))
    lib.rk_frame_to_rgb.argtypes = [
        ctypes.c_void_p, ctypes.c_size_t, ctypes.c_uint, ctypes.c_uint, ctypes.c_int, ctypes.c_void_p,
    ]
    lib.rk_frame_to_rgb.restype = ctypes.c_int
    lib.rk_rand_seed.argtypes = [ctypes.POINTER(Rand), ctypes.c_uint]
    lib.rk_rand_next.argtypes = [ctypes.POINTER(Rand)]
    lib.rk_rand_next.restype = ctypes.c_int32
    return lib
