"""Damaged copies of a libretro core: refused with CoreError before loading, and never a file left behind.

Each case puts a damaged genesis_plus_gx core first in RETROKIT_CORES and
opens Dasher in a child process whose TMPDIR is a fresh folder, where the
host makes its private copies of the core.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from pathlib import Path

import pytest
from childproc import run_child

from retrokit.host.cores import core_filename, find_core
from retrokit.paths import wheel_cores_dir

CORE = find_core("genesis_plus_gx")
OPEN = """
from retrokit.errors import CoreError
from retrokit.host.emulator import Emulator
try:
    Emulator("Genesis", "games/Dasher-Genesis/rom.md").close()
    print("loaded")
except CoreError as exc:
    print("refused:", exc)
"""


def _truncate(size: int) -> Callable[[bytes], bytes]:
    return lambda data: data[:size]


def _program_headers_past_the_end(data: bytes) -> bytes:
    return data[:0x20] + struct.pack("<Q", len(data) + 4096) + data[0x28:]  # e_phoff


def _relocations_damaged(data: bytes) -> bytes:
    # Relocation targets far outside the library: the loader writes there while dlopen runs.
    rela_dyn = 0x1140  # where the wheel's Genesis Plus GX keeps .rela.dyn (checked below)
    out = bytearray(data)
    for at in range(rela_dyn, rela_dyn + 24 * 2000, 24):
        out[at : at + 8] = (0x7FFFFFFFFFFF00).to_bytes(8, "little")
    return bytes(out)


REFUSED = {
    "truncated-to-half": (_truncate(len(CORE.read_bytes()) // 2), "is truncated or damaged"),
    "truncated-to-1500000-bytes": (_truncate(1_500_000), "is truncated or damaged"),
    "truncated-inside-the-header": (_truncate(32), "expected an ELF file"),
    "not-an-elf-file": (lambda data: b"#!/bin/sh\necho not a core\n" * 100, "expected an ELF file"),
    "program-headers-past-the-end": (_program_headers_past_the_end, "is truncated or damaged"),
}


def _install(tmp_path: Path, damage: Callable[[bytes], bytes]) -> dict[str, str]:
    cores, tmp = tmp_path / "cores", tmp_path / "tmp"
    cores.mkdir()
    tmp.mkdir()
    (cores / core_filename("genesis_plus_gx")).write_bytes(damage(CORE.read_bytes()))
    return {"RETROKIT_CORES": str(cores), "TMPDIR": str(tmp)}


@pytest.mark.parametrize("case", list(REFUSED), ids=list(REFUSED))
def test_a_damaged_core_is_refused_before_loading(tmp_path: Path, case: str) -> None:
    damage, message = REFUSED[case]
    child = run_child(OPEN, env=_install(tmp_path, damage), timeout=60)
    assert child.returncode == 0, child.describe()
    assert "refused:" in child.stdout and message in child.stdout, child.describe()
    assert list((tmp_path / "tmp").iterdir()) == []


def test_a_core_that_crashes_while_loading_leaves_no_copy_behind(tmp_path: Path) -> None:
    import subprocess

    sections = subprocess.run(["readelf", "-SW", str(CORE)], capture_output=True, text=True, check=False).stdout
    if " .rela.dyn " not in sections or " 001140 " not in sections.split(" .rela.dyn ")[1].splitlines()[0]:
        pytest.skip("this Genesis Plus GX build keeps its relocations elsewhere")
    child = run_child(OPEN, env=_install(tmp_path, _relocations_damaged), timeout=60)
    # The ELF is well formed, so nothing refuses it and the loader may crash; either way no copy is left.
    assert child.signal in (None, "SIGSEGV", "SIGBUS"), child.describe()
    assert list((tmp_path / "tmp").iterdir()) == []


def test_side_by_side_emulators_still_get_private_copies(dasher_rom: Path) -> None:
    from retrokit.host.emulator import Emulator

    with Emulator("Genesis", dasher_rom) as one, Emulator("Genesis", dasher_rom) as two:
        one.run(0, 30)
        assert one.frame == 30 and two.frame == 0  # separate globals: separate frame counters and RAM
        one.ram[0] = 0x55
        two.ram[0] = 0xAA
        assert one.ram[0] == 0x55


@pytest.mark.parametrize("core", sorted(wheel_cores_dir().glob("*_libretro.so")), ids=lambda p: p.name)
def test_every_wheel_core_passes_the_elf_check(core: Path) -> None:
    from retrokit.host.elf import check_core_file

    check_core_file(core)
