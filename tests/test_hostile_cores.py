"""Damaged copies of a libretro core: refused with CoreError before loading, and never a file left behind.

Each case puts a damaged genesis_plus_gx core first in RETROKIT_CORES and
opens Dasher in a child process whose TMPDIR is a fresh folder, where the
host makes its private copies of the core.
"""

from __future__ import annotations

import hashlib
import json
import random
import struct
from collections.abc import Callable
from pathlib import Path

import pytest
from childproc import run_child

from retrokit.errors import CoreError
from retrokit.host.cores import core_filename
from retrokit.host.emulator import Emulator
from retrokit.paths import wheel_cores_dir

CORE = wheel_cores_dir() / core_filename("genesis_plus_gx")  # the wheel's, whose layout the cases know
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
    return {"RETROKIT_CORES": str(cores), "TMPDIR": str(tmp), "RETROKIT_DATA": str(tmp_path / "data")}  # verdicts kept there


@pytest.mark.parametrize("case", list(REFUSED), ids=list(REFUSED))
def test_a_damaged_core_is_refused_before_loading(tmp_path: Path, case: str) -> None:
    damage, message = REFUSED[case]
    child = run_child(OPEN, env=_install(tmp_path, damage), timeout=60)
    assert child.returncode == 0, child.describe()
    assert "refused:" in child.stdout and message in child.stdout, child.describe()
    assert list((tmp_path / "tmp").iterdir()) == []


def test_a_core_that_crashes_while_loading_is_refused_and_leaves_no_copy_behind(tmp_path: Path) -> None:
    if sections(CORE).get(".rela.dyn", (0, 0))[0] != 0x1140:
        pytest.skip("this Genesis Plus GX build keeps its relocations elsewhere")
    child = run_child(OPEN, env=_install(tmp_path, _relocations_damaged), timeout=120)
    # The ELF is well formed, so only the probe finds the loader crashing on it; its copy, too, is gone.
    assert child.returncode == 0 and "refused:" in child.stdout and "crashed the probe" in child.stdout, child.describe()
    assert list((tmp_path / "tmp").iterdir()) == []


def sections(path: Path) -> dict[str, tuple[int, int]]:
    """A 64-bit little-endian ELF file's sections: name -> (file offset, size)."""
    data = path.read_bytes()
    shoff, = struct.unpack_from("<Q", data, 0x28)
    shentsize, shnum, shstrndx = struct.unpack_from("<HHH", data, 0x3A)
    headers = [struct.unpack_from("<IIQQQQ", data, shoff + i * shentsize) for i in range(shnum)]
    names = headers[shstrndx][4]
    found = {}
    for name, _, _, _, offset, size in headers:
        end = data.index(b"\0", names + name)
        found[data[names + name : end].decode()] = (offset, size)
    return found


def _section_damage(name: str, damage: Callable[[bytes], bytes]) -> Callable[[bytes], bytes]:
    def apply(data: bytes) -> bytes:
        offset, size = sections(CORE)[name]
        return data[:offset] + damage(data[offset : offset + size]) + data[offset + size :]

    return apply


def _flip_every(step: int) -> Callable[[bytes], bytes]:
    return lambda part: bytes(b ^ 0xFF if i % step == 0 else b for i, b in enumerate(part))


# Damage the ELF check cannot see: the headers are intact, the insides are not.
PROBED = {
    "dynamic-section-zeroed": _section_damage(".dynamic", lambda part: bytes(len(part))),
    "dynsym-randomised": _section_damage(".dynsym", lambda part: random.Random(7).randbytes(len(part))),
    "text-bytes-flipped": _section_damage(".text", _flip_every(97)),
}


@pytest.mark.parametrize("case", list(PROBED), ids=list(PROBED))
def test_a_core_damaged_inside_is_probed_and_refused_in_one_line(tmp_path: Path, case: str) -> None:
    child = run_child(OPEN, env=_install(tmp_path, PROBED[case]), timeout=120)
    assert child.returncode == 0 and child.signal is None, child.describe()
    (line,) = child.stdout.splitlines()
    assert line.startswith("refused: ") and "is not a core retrokit can load" in line, line
    assert "crashed the probe (SIG" in line or "hangs" in line, line
    assert list((tmp_path / "tmp").iterdir()) == []
    if "hangs" not in line:  # a crash is a lasting verdict, kept by the core's SHA-256; a hang is probed again
        (verdict,) = (tmp_path / "data" / "core-probes").iterdir()
        digest = hashlib.sha256((tmp_path / "cores" / core_filename("genesis_plus_gx")).read_bytes()).hexdigest()
        assert verdict.name == digest and "crashed the probe" in verdict.read_text()


def test_a_kept_verdict_refuses_without_probing_again(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, dasher_rom) -> None:
    from retrokit.host import corecheck

    core = tmp_path / core_filename("genesis_plus_gx")
    core.write_bytes(PROBED["dynamic-section-zeroed"](CORE.read_bytes()))
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    verdict = tmp_path / "data" / "core-probes" / hashlib.sha256(core.read_bytes()).hexdigest()
    verdict.parent.mkdir(parents=True)
    verdict.write_text("it crashed the probe (SIGSEGV) while loading or within 60 frames")

    def no_probe(*args: object, **kwargs: object) -> None:
        raise AssertionError("probed again")

    monkeypatch.setattr(corecheck, "probe_core", no_probe)
    with pytest.raises(CoreError, match=r"crashed the probe \(SIGSEGV\).*delete that file to probe the core again"):
        Emulator("Genesis", dasher_rom, core_path=core)


def test_a_copy_of_a_wheel_core_is_trusted_by_its_digest(tmp_path, monkeypatch, dasher_rom) -> None:
    from retrokit.host import corecheck

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    monkeypatch.setattr(corecheck, "probe_core", lambda *args, **kwargs: pytest.fail("a known core was probed"))
    copy = tmp_path / core_filename("genesis_plus_gx")
    copy.write_bytes(CORE.read_bytes())
    with Emulator("Genesis", dasher_rom, core_path=copy) as emulator:
        emulator.run(0, 10)
    assert not (tmp_path / "data" / "core-probes").exists()


def test_the_wheel_record_vouches_for_every_wheel_core() -> None:
    from retrokit.host.corecheck import file_sha256, wheel_vouchers

    vouchers = wheel_vouchers()
    cores = sorted(wheel_cores_dir().glob("*_libretro.so"))
    assert cores and {path.resolve() for path in cores} <= set(vouchers)
    for path in cores:
        assert vouchers[path.resolve()].sha256 == file_sha256(path), path


def test_a_damaged_core_at_a_vouched_place_is_refused_with_how_to_restore_it(tmp_path, monkeypatch, dasher_rom) -> None:
    """A wheel core and a built core that differ from their records: refused before loading, by the digest alone."""
    from retrokit.host import corecheck
    from retrokit.host.cores import built_cores_dir

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    monkeypatch.setattr(corecheck, "probe_core", lambda *args, **kwargs: pytest.fail("a vouched core was probed"))
    built = built_cores_dir() / core_filename("genesis_plus_gx")
    built.parent.mkdir(parents=True)
    built.write_bytes(CORE.read_bytes())
    record = {"core": "genesis_plus_gx", "stable_retro": "1.0.1", "library_sha256": hashlib.sha256(built.read_bytes()).hexdigest()}
    (built_cores_dir() / "genesis_plus_gx.build.json").write_text(json.dumps(record))
    with Emulator("Genesis", dasher_rom, core_path=built) as emulator:  # intact: its record vouches for it
        emulator.run(0, 10)
    built.write_bytes(_section_damage(".text", _flip_every(4096))(CORE.read_bytes()))  # one byte in 4096: a bit rot
    with pytest.raises(CoreError, match=r"is damaged: its SHA-256 is .* but its build record .* retrokit build-core genesis_plus_gx --force"):
        Emulator("Genesis", dasher_rom, core_path=built)

    wheel_like = tmp_path / "wheel" / core_filename("genesis_plus_gx")  # where a RECORD says which bytes belong
    wheel_like.parent.mkdir()
    wheel_like.write_bytes(built.read_bytes())
    voucher = corecheck.Voucher(hashlib.sha256(CORE.read_bytes()).hexdigest(), "stable-retro 1.0.1's RECORD", "Reinstall it")
    monkeypatch.setattr(corecheck, "wheel_vouchers", lambda: {wheel_like.resolve(): voucher})
    with pytest.raises(CoreError, match=r"but stable-retro 1.0.1's RECORD says .*Reinstall it"):
        Emulator("Genesis", dasher_rom, core_path=wheel_like)


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


def test_the_probe_keeps_under_a_users_memory_limit(tmp_path: Path) -> None:
    """Under ``ulimit -v`` (1 GiB) the probe's child starts within the user's limit: a verdict, never a raw error."""
    limited = "import resource\nresource.setrlimit(resource.RLIMIT_AS, (2**30, 2**30))\n" + OPEN
    child = run_child(limited, env=_install(tmp_path, PROBED["dynamic-section-zeroed"]), timeout=120)
    assert child.returncode == 0 and child.signal is None, child.describe()
    (line,) = child.stdout.splitlines()
    assert line.startswith("refused: ") and "is not a core retrokit can load" in line, line
    assert "preexec_fn" not in line and "Traceback" not in child.stderr, child.describe()
