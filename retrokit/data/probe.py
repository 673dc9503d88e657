"""Probing a save state in a child process, so a state that crashes the core cannot kill the caller.

Genesis Plus GX trusts a state's contents: a state with the right size and a
valid header but a corrupt body makes it crash (SIGSEGV) on the next frame.
Such a state is caught by loading it into a fresh emulator in a child
process and running a few seconds of frames; the child dying by a signal, or
hanging, marks the state unsafe. The verdict is cached in the data folder
(``<data>/state-probes/``) under the SHA-256 of the system, the ROM's SHA-1
and the state, so each state is probed once per machine.

Run as ``python -m retrokit.data.probe SYSTEM ROM STATE_FILE FRAMES``, this
module is the child.
"""

from __future__ import annotations

import hashlib
import os
import resource
import signal
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from retrokit import paths
from retrokit.errors import RetrokitError, StateError
from retrokit.host.systems import System, get_system

PROBE_FRAMES = 300
"""Frames run from a probed state: five seconds of play, long enough for a corrupt body to show."""
PROBE_TIMEOUT = 60.0
"""Seconds a probe may take before the state counts as one that hangs the core."""
_REFUSED = 3  # the child's exit status when retrokit refused the state with an error
_SAFE = "safe"


@dataclass(frozen=True)
class ProbeVerdict:
    """What probing a state found.

    Attributes:
        safe: The state loaded and ran its frames in the child.
        reason: Why it is not safe (empty when it is): the signal, a hang, or retrokit's error.
    """

    safe: bool
    reason: str = ""


def probe_key(state: bytes, system: str, rom_sha1: str) -> str:
    """The cache key of a probe: SHA-256 of the system, the ROM's SHA-1 and the state."""
    digest = hashlib.sha256(f"{system}\0{rom_sha1}\0".encode())
    digest.update(state)
    return digest.hexdigest()


def _child_env() -> dict[str, str]:
    """This process's environment, with the folder retrokit was imported from first on the path."""
    root = str(Path(__file__).resolve().parents[2])
    path = os.environ.get("PYTHONPATH")
    return {**os.environ, "PYTHONPATH": root + (os.pathsep + path if path else "")}


def _child_limits() -> None:
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))  # a crashing probe leaves no core file


def probe_state(
    state: bytes, system: str | System, rom: str | os.PathLike[str], *, frames: int = PROBE_FRAMES,
    timeout: float = PROBE_TIMEOUT,
) -> ProbeVerdict:
    """Load ``state`` on ``rom`` in a child process and run ``frames`` frames; report how the child ended.

    This is not cached: see :func:`vet_state`.

    Args:
        state: The serialized state (uncompressed).
        system: The system (a name or descriptor).
        rom: The ROM to load it on.
        frames: How many frames to run after loading it.
        timeout: Seconds before the child counts as hung, and is killed.
    """
    system = get_system(system).name
    with tempfile.NamedTemporaryFile(prefix="retrokit-probe-", suffix=".bin") as tmp:
        tmp.write(state)
        tmp.flush()
        command = [sys.executable, "-m", "retrokit.data.probe", system, os.fspath(rom), tmp.name, str(frames)]
        try:
            done = subprocess.run(
                command, capture_output=True, text=True, timeout=timeout, check=False, stdin=subprocess.DEVNULL,
                preexec_fn=_child_limits, env=_child_env(),
            )
        except subprocess.TimeoutExpired:
            return ProbeVerdict(False, f"the emulator still ran {timeout:.0f} s after loading it (it hangs the core)")
    if done.returncode == 0:
        return ProbeVerdict(True)
    if done.returncode < 0:
        name = signal.Signals(-done.returncode).name
        return ProbeVerdict(False, f"the emulator crashed ({name}) within {frames} frames of loading it")
    message = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
    if done.returncode == _REFUSED:
        return ProbeVerdict(False, message)
    return ProbeVerdict(False, f"the probe failed with exit status {done.returncode}: {message}")


def _cache_file(key: str, data_dir: Path | None) -> Path:
    return (data_dir if data_dir is not None else paths.data_dir()) / "state-probes" / key


def _cached(key: str, data_dir: Path | None) -> ProbeVerdict | None:
    try:
        text = _cache_file(key, data_dir).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    return ProbeVerdict(True) if text == _SAFE else ProbeVerdict(False, text)


def _remember(key: str, verdict: ProbeVerdict, data_dir: Path | None) -> None:
    try:
        paths.atomic_write(_cache_file(key, data_dir), (_SAFE if verdict.safe else verdict.reason).encode(), overwrite=True)
    except OSError:
        pass  # an unwritable data folder only means probing again next time


def vet_state(
    state: bytes, system: str | System, rom: str | os.PathLike[str], rom_sha1: str, *, source: str,
    data_dir: str | os.PathLike[str] | None = None,
) -> None:
    """Refuse a state that crashes or hangs the core, probing it in a child once per machine.

    Args:
        state: The serialized state.
        system: The system's name.
        rom: The ROM the state is for.
        rom_sha1: The ROM's SHA-1 (part of the cache key).
        source: What to call the state in the error (its path, or a movie's Core.bin).
        data_dir: The data folder holding the cache; by default :func:`retrokit.paths.data_dir`.

    Raises:
        StateError: The state crashed, hung or was refused in the child.
    """
    system = get_system(system).name
    folder = Path(data_dir) if data_dir is not None else None
    key = probe_key(state, system, rom_sha1)
    verdict = _cached(key, folder)
    if verdict is None:
        verdict = probe_state(state, system, rom)
        _remember(key, verdict, folder)
    if not verdict.safe:
        raise StateError(
            f"{source}: expected a save state the {system} core can run; found one that it cannot: "
            f"{verdict.reason}. The file is corrupt or was made by something else; record or copy it again."
        )


def _child(argv: list[str]) -> int:
    """Load the state and run its frames; exit 0, or 3 with retrokit's error on the last line of stderr."""
    from retrokit.host.emulator import Emulator

    system, rom, state_file, frames = argv
    try:
        with Emulator(system, rom) as emu:
            emu.set_state(Path(state_file).read_bytes())
            emu.run(0, int(frames))
            emu.get_state()
    except (RetrokitError, ValueError) as exc:
        print(str(exc).replace("\n", " "), file=sys.stderr)
        return _REFUSED
    return 0


if __name__ == "__main__":
    sys.exit(_child(sys.argv[1:]))
