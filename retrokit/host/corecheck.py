"""Vetting a core before it is loaded: a damaged core ends in a CoreError, never in a signal.

The dynamic loader trusts a shared library. A core with its ``.dynamic``
section zeroed or its ``.dynsym`` scrambled crashes the process inside
``dlopen``; flipped bytes in ``.text`` crash it at the first frame. The ELF
check (:mod:`retrokit.host.elf`) sees none of that, so before a core is
loaded, :func:`vet_core` also asks who vouches for its bytes:

1. The stable-retro wheel's ``RECORD`` lists the SHA-256 of every core it
   ships, and ``retrokit build-core`` records the SHA-256 of what it built
   (``<data>/cores/<core>.build.json``). A core at one of those places with
   other bytes is damaged, and refused with how to restore it; a core
   elsewhere with one of those digests is a copy, and trusted.
2. Any other core (one named by ``RETROKIT_CORES`` or ``core_path``, a
   system's libretro folder) is probed once: a child process loads it with
   the ROM at hand and runs a few frames. The verdict is kept in the data
   folder under the core's SHA-256 (``<data>/core-probes/``), so each content
   is probed once per machine.

Trust comes only from what the package installed or this machine wrote, never
from the bytes of the core itself. A file is hashed once per process (cached
by path, size, modification time and inode).

The probe's child is :mod:`retrokit.host.coreprobe`, run as every risky child is (:mod:`retrokit.host.child`).
"""

from __future__ import annotations

import functools
import hashlib
import os
from dataclasses import dataclass
from pathlib import Path

from retrokit.errors import ChildStartError, CoreError
from retrokit.host.child import Child
from retrokit.host.cores import built_cores_dir, core_filename, read_build_record
from retrokit.host.elf import check_core_file
from retrokit.host.verdicts import ProbeVerdict, keep_verdict, kept_verdict
from retrokit.paths import data_dir
from retrokit.wheel import wheel_files, wheel_version

PROBE_FRAMES = 60
"""Frames the probe runs after loading: a damaged ``.text`` shows within the first."""
PROBE_TIMEOUT = 30.0
"""Seconds a probe may take before the core counts as one that hangs."""
PROBE_ADDRESS_SPACE = 3 * 2**30
"""The probe's address-space cap: far above what Python, numpy and a core map, far below a runaway."""
REFUSED = 3
"""The child's exit status when retrokit refused the core with its own error."""

_StatKey = tuple[str, int, int, int]
_digests: dict[_StatKey, str] = {}  # SHA-256 by (path, size, mtime, inode): each file hashed once per process
_vetted: set[_StatKey] = set()


@dataclass(frozen=True)
class Voucher:
    """Who vouches for the bytes of a core at one path.

    Attributes:
        sha256: The digest its bytes must have.
        source: Who says so, for messages (``"stable-retro 1.0.1's RECORD"``).
        fix: How to get the right bytes back.
    """

    sha256: str
    source: str
    fix: str


def _stat_key(path: Path) -> _StatKey:
    info = path.stat()
    return (str(path.resolve()), info.st_size, info.st_mtime_ns, info.st_ino)


def file_sha256(path: Path) -> str:
    """Return the SHA-256 of a file, hashing it once per process while it is unchanged."""
    key = _stat_key(path)
    if key not in _digests:
        digest = hashlib.sha256()
        with path.open("rb") as file:
            for block in iter(lambda: file.read(1 << 20), b""):
                digest.update(block)
        _digests[key] = digest.hexdigest()
    return _digests[key]


@functools.lru_cache(maxsize=1)
def wheel_vouchers() -> dict[Path, Voucher]:
    """Return the stable-retro wheel's cores by path, with the SHA-256 its ``RECORD`` lists for each."""
    version = wheel_version()
    source = f"stable-retro {version}'s RECORD"
    fix = "Reinstall it: pip install --force-reinstall --no-deps stable-retro"
    return {
        where.resolve(): Voucher(digest, source, fix)
        for _, where, digest in wheel_files(lambda path: "_libretro." in path.rpartition("/")[2])
    }


def built_vouchers(data: Path | None = None) -> dict[Path, Voucher]:
    """Return the cores ``retrokit build-core`` made, by path, with the SHA-256 each build record holds."""
    found = {}
    for record_path in sorted(built_cores_dir(data).glob("*.build.json")):
        record = read_build_record(record_path.name.removesuffix(".build.json"), data) or {}
        if "core" not in record or "library_sha256" not in record:
            continue  # no readable record vouches for nothing
        core, digest = str(record["core"]), str(record["library_sha256"])
        fix = f"Build it again: retrokit build-core {core} --force"
        found[(built_cores_dir(data) / core_filename(core)).resolve()] = Voucher(digest, f"its build record {record_path}", fix)
    return found


def vet_core(core: str | os.PathLike[str], system: str, rom: str | os.PathLike[str]) -> None:
    """Raise unless ``core`` is safe to load into this process (see the module's docstring).

    Args:
        core: The core's shared library.
        system: The system it is loaded for (the probe's child opens the same).
        rom: The ROM it is loaded with (the probe's child runs it).

    Raises:
        CoreError: The core is no whole shared library, differs from what its
            wheel or build recorded, or crashed or hung the probe.
    """
    path = Path(core)
    check_core_file(path)
    try:
        key = _stat_key(path)
        if key in _vetted:
            return
        digest = file_sha256(path)
    except OSError as exc:
        raise CoreError(f"Expected a readable core at {path}; found an error: {exc.strerror or exc}.") from None
    vouchers = {**wheel_vouchers(), **built_vouchers()}
    voucher = vouchers.get(path.resolve())
    if voucher is not None and voucher.sha256 != digest:
        raise CoreError(
            f"{path} is damaged: its SHA-256 is {digest[:16]}..., but {voucher.source} says "
            f"{voucher.sha256[:16]}.... {voucher.fix}."
        )
    if voucher is None and digest not in {v.sha256 for v in vouchers.values()}:
        verdict = kept_verdict(CORE_PROBES, digest, "a core's verdict")
        if verdict is None:
            verdict = probe_core(path, system, rom)
            keep_verdict(CORE_PROBES, digest, verdict)
        if not verdict.safe:
            raise CoreError(
                f"{path} is not a core retrokit can load: {verdict.reason}. Use the stable-retro wheel's core "
                f"(remove this one from RETROKIT_CORES), or rebuild it; the verdict is kept in {data_dir() / CORE_PROBES / digest} "
                "(delete that file to probe the core again)."
            )
    _vetted.add(key)


def probe_core(core: Path, system: str, rom: str | os.PathLike[str], *, timeout: float = PROBE_TIMEOUT) -> ProbeVerdict:
    """Load ``core`` with ``rom`` in a child process and run :data:`PROBE_FRAMES` frames; report how it ended."""
    request = {"system": system, "rom": os.fspath(rom), "core": os.fspath(core)}
    try:
        with Child("retrokit.host.coreprobe", request, memory=PROBE_ADDRESS_SPACE) as child:
            for _ in child.lines(first=timeout):  # it prints nothing: all of it must be done in time
                pass
            end = child.end()
    except ChildStartError as exc:  # a child that failed before it ran (no memory, no processes)
        return ProbeVerdict(False, f"the probe could not start: {exc.reason}", lasting=False)
    if end.hung:
        return ProbeVerdict(False, f"it still ran {timeout:.0f} s after loading (it hangs)", lasting=end.lasting)
    if end.status in (0, REFUSED):
        return ProbeVerdict(True)
    if end.signal is not None:
        return ProbeVerdict(False, f"it crashed the probe ({end.signal}) while loading or within {PROBE_FRAMES} frames")
    return ProbeVerdict(False, f"the probe failed (exit {end.status}: {end.last_words})", lasting=False)


CORE_PROBES = "core-probes"
"""The data folder's folder of core verdicts (:mod:`retrokit.host.verdicts`: never through a link)."""


def mark_probing(core: Path) -> None:
    """Let this process load ``core`` unvetted: only the probe's child does, since it is the probe."""
    _vetted.add(_stat_key(core))
