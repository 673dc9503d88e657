"""Checking a core's shared library before the loader maps it.

A truncated or damaged library makes the dynamic loader fault (SIGBUS on the
pages past the end of the file, SIGSEGV on headers that point nowhere), which
would take the whole process down. So before a core is loaded, its ELF
header must be this machine's kind of shared library, and every program
segment and the section table it names must lie inside the file.
"""

from __future__ import annotations

import os
import platform
import struct
from pathlib import Path
from typing import BinaryIO

from retrokit.errors import CoreError

_MAGIC = b"\x7fELF"
_ET_DYN = 3
# ELF machine numbers (elf.h) of the machines retrokit's host builds on.
_MACHINES = {"x86_64": 62, "amd64": 62, "aarch64": 183, "arm64": 183, "i386": 3, "i686": 3, "armv7l": 40}


def check_core_file(path: str | os.PathLike[str]) -> None:
    """Raise unless ``path`` is a whole shared library for this machine.

    Raises:
        CoreError: It is no ELF file, is built for another machine, or its
            headers describe more bytes than the file has (truncated or damaged).
    """
    path = Path(path)
    try:
        with path.open("rb") as file:
            size = os.fstat(file.fileno()).st_size
            header = file.read(64)
            if len(header) < 52 or header[:4] != _MAGIC or header[4] not in (1, 2) or header[5] not in (1, 2):
                raise CoreError(
                    f"{path} is not a shared library: expected an ELF file; found another kind of file, "
                    "or one too short for an ELF header. Reinstall the core (pip install --force-reinstall stable-retro)."
                )
            need = _extent(file, header)
    except OSError as exc:
        raise CoreError(f"Expected a readable core at {path}; found an error: {exc.strerror}.") from exc
    if need > size:
        raise CoreError(
            f"{path} is truncated or damaged: its ELF headers describe {need} bytes; the file has {size}. "
            "Reinstall the core (pip install --force-reinstall stable-retro), or rebuild it (retrokit build-core)."
        )


def _extent(file: BinaryIO, header: bytes) -> int:
    """The bytes the headers say the file holds: program headers, their segments, and the section table."""
    wide = header[4] == 2
    order = "<" if header[5] == 1 else ">"
    if wide:
        e_type, e_machine = struct.unpack_from(order + "HH", header, 16)
        e_phoff, e_shoff = struct.unpack_from(order + "QQ", header, 32)
        e_phentsize, e_phnum, e_shentsize, e_shnum = struct.unpack_from(order + "HHHH", header, 54)
    else:
        e_type, e_machine = struct.unpack_from(order + "HH", header, 16)
        e_phoff, e_shoff = struct.unpack_from(order + "II", header, 28)
        e_phentsize, e_phnum, e_shentsize, e_shnum = struct.unpack_from(order + "HHHH", header, 42)
    machine = _MACHINES.get(platform.machine().lower())
    ours = wide == (struct.calcsize("P") == 8) and e_type == _ET_DYN and e_phentsize == (56 if wide else 32)
    if not ours or (machine is not None and e_machine != machine):
        raise CoreError(
            f"{file.name} is not a shared library for this machine (ELF class {header[4]}, type {e_type}, "
            f"machine {e_machine}). Use a core built for {platform.machine()}."
        )
    need = max(e_phoff + e_phnum * e_phentsize, e_shoff + e_shnum * e_shentsize if e_shnum else 0)
    file.seek(e_phoff)
    table = file.read(e_phnum * e_phentsize)
    for i in range(len(table) // e_phentsize):
        if wide:
            p_offset, _, _, p_filesz = struct.unpack_from(order + "QQQQ", table, i * e_phentsize + 8)
        else:
            p_offset, _, _, p_filesz = struct.unpack_from(order + "IIII", table, i * e_phentsize + 4)
        need = max(need, p_offset + p_filesz)
    return need
