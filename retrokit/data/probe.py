"""The one gate between a state's bytes and a core: trust by this machine's records, else a probe in a child.

Genesis Plus GX trusts a state's contents: a state with the right size and a
valid header but a corrupt body makes it crash (SIGSEGV), on the next frame,
on the second load or only under input. So a state reaches an emulator only
as a :class:`~retrokit.host.emulator.VettedState`, and this module holds the
only way to make one from bytes (it claims the mint when imported). It makes
one when:

- the bytes are a state file retrokit or the stable-retro wheel ships, by the
  SHA-256 of the file (:mod:`retrokit.data.shipped`);
- this machine probed the state before and found it safe, or retrokit wrote
  it from a core (:func:`remember`): verdicts are kept in the data folder
  (``<data>/state-probes/``) under the SHA-256 of the system, the ROM's SHA-1
  and the state;
- never when its bytes would make the core build a pointer outside its own
  memory (:mod:`retrokit.host.statelayout`): whether that crashes depends on
  the process's memory layout, so no probe or record can vouch for it;
- otherwise, once it has passed the probe: loaded into a fresh emulator in a
  child process, run, loaded again, run 3,000 frames under random input, and
  loaded twice more around one frame (as an env's reset() does). The child
  dying by a signal, running out of memory, or hanging marks it unsafe.

Nothing inside the file (retrokit's ``RK`` record, a movie's header) makes a
state trusted: a record may only refuse one (:mod:`retrokit.data.statecheck`).

The child (``python -m retrokit.data.probe``, reading a JSON request on
stdin) loads each state of the request in turn and answers one JSON line
before and one after each, with the fields' values, on the answer channel
of :mod:`retrokit.host.child` (a pipe of its own: the core prints on stdout,
and pce_fast prints bytes a state chooses there). ``retrokit validate``
(:mod:`retrokit.testing.states`) asks the same probe for its report per state
(:func:`probe_files`). The child runs as every risky child does: under a
memory cap, with no core file, importing the retrokit its parent imported,
killed with its process group if it hangs; how it ended is read before what
it answered.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from retrokit.data.shipped import is_shipped_blob
from retrokit.data.states import MAX_STATE_FILE_SIZE, decompress_state
from retrokit.errors import RetrokitError, StateError
from retrokit.host.child import Child
from retrokit.host.emulator import VettedState, claim_mint
from retrokit.host.statelayout import state_layout_problem
from retrokit.host.systems import System, get_system
from retrokit.host.verdicts import ProbeVerdict, keep_verdict, kept_verdict

_mint = claim_mint()

PROBE_FRAMES = 300
"""Idle frames run from a probed state after its first load."""
PROBE_INPUT_FRAMES = 3000
"""Frames of random input run after the second load: a corrupt body may crash the core only thousands of frames
in (where depends on the process's memory layout), so the probe plays as long as a short episode."""
PROBE_TIMEOUT = 60.0
"""Seconds a child may run one state before the state counts as one that hangs the core."""
CHILD_STARTUP = 120.0
"""Seconds a child may take to start (importing retrokit, loading the core) on a busy machine."""
CHILD_MEMORY = 512 << 20
"""Bytes of address space a child may map: a state that makes the core allocate wildly fails there."""


# --- The child's results -------------------------------------------------------------------------


@dataclass
class ChildResult:
    """What the child found of one state.

    Attributes:
        name: The state's name in the request.
        path: Its file.
        loaded: It loaded, ran, loaded again and ran under input.
        error: Why it did not: retrokit's error, a signal, a hang (``""`` when it did).
        start: Every field's value right after the first load, by name.
        first: Every field's value one idle frame in (what validate checks ranges on).
        after: Every field's value after the idle frames.
        detail: The core's signature and the state's size.
    """

    name: str
    path: str
    loaded: bool = False
    error: str = ""
    start: dict[str, int] = field(default_factory=dict)
    first: dict[str, int] = field(default_factory=dict)
    after: dict[str, int] = field(default_factory=dict)
    detail: str = ""


def run_child(
    system: str, rom: str | os.PathLike[str], states: Sequence[tuple[str, str, int, int]], *,
    fields: Sequence[Mapping[str, Any]] = (), timeout: float | None = None,
) -> tuple[dict[str, ChildResult], str | None, ProbeVerdict | None]:
    """Run one child over ``states``; return the results it finished, the state to blame if it failed, and the
    failure's verdict (``None`` if the child ended well; a hang's is not lasting: :attr:`ChildEnd.lasting`).

    The child (run as every risky child is: :mod:`retrokit.host.child`) answers
    on a pipe of its own, a line before and after each state; a state that
    answers nothing for ``timeout`` seconds has hung the core, and the child
    is killed. A child that died by a signal, hung or failed proves nothing
    of any state it ran, whatever it answered before: its results are
    dropped, and the state it was on (or, between two, the last it finished)
    is blamed.

    Args:
        system: The system's name.
        rom: The ROM to load the states on.
        states: ``(name, path, frames, input_frames)`` of each state file, in order: idle frames to
            run after its first load, then frames of random input after loading it again.
        fields: RAM fields (``name``, ``address``, ``type``, ``mask``) to read after loading.
        timeout: Seconds one state may take (by default :data:`PROBE_TIMEOUT`).

    Raises:
        ChildStartError: The child could not start.
    """
    timeout = PROBE_TIMEOUT if timeout is None else timeout
    request = {"system": system, "rom": os.fspath(rom), "fields": list(fields), "states": [list(s) for s in states]}
    results: dict[str, ChildResult] = {}
    current = None
    with Child("retrokit.data.probe", request, memory=CHILD_MEMORY) as child:
        for line in child.lines(first=CHILD_STARTUP + timeout, each=timeout):
            try:  # only the child's own code writes on its channel; a torn line from a crash is no answer
                message = json.loads(line)
                if "begin" in message:
                    current = message["begin"]
                else:
                    results[message["name"]] = ChildResult(**message)
                    current = None
            except (ValueError, TypeError, KeyError):
                continue
        end = child.end()
    if end.hung:
        failure = f"the emulator still ran {timeout:g} s after loading it (it hangs the core)"
    elif end.signal is not None:
        failure = f"the emulator crashed ({end.signal}) within the frames run after loading it"
    elif end.status != 0:
        failure = f"the state loader exited with status {end.status}: {end.last_words}"
    else:
        return results, None, None
    blamed = current if current is not None else next(reversed(results), None)
    return {}, blamed, ProbeVerdict(False, failure, lasting=end.lasting)


def probe_files(
    system: str, rom: str | os.PathLike[str], rom_sha1: str, files: Mapping[str, str | os.PathLike[str]], *,
    frames: int = PROBE_FRAMES, fields: Sequence[Mapping[str, Any]] = (), timeout: float | None = None,
) -> dict[str, ChildResult]:
    """Try each state file on ``rom`` in a child, by the one rule :func:`vet_state` trusts a state by; return each
    one's result (``retrokit validate``'s view: every field's values, not only a verdict).

    A state this machine knows (shipped, or probed here before: :func:`vet_state`'s
    order of trust) is loaded and run ``frames`` idle frames; a state it knows
    to be unsafe fails with the known reason; any other is probed as
    :func:`vet_state` probes it (at least :data:`PROBE_FRAMES` idle frames,
    then :data:`PROBE_INPUT_FRAMES` under input, reloads around them), and its
    verdict is kept as :func:`vet_state` keeps it. A child that dies or hangs
    fails the state it was blamed on (:func:`run_child`), and a new child
    carries on with the others.

    Args:
        system: The system's name.
        rom: The ROM.
        rom_sha1: Its SHA-1 (the verdicts' key).
        files: Each state's file, by name.
        frames: Idle frames to run after each state's first load.
        fields: RAM fields to read (see :func:`run_child`).
        timeout: Seconds one state may take (by default :data:`PROBE_TIMEOUT`).
    """
    from retrokit.data.states import read_state

    results: dict[str, ChildResult] = {}
    plans: dict[str, tuple[str, str, int, int]] = {}
    keys: dict[str, str] = {}
    for name, path in files.items():
        try:
            state = read_state(path)
        except RetrokitError as exc:
            results[name] = ChildResult(name, os.fspath(path), error=str(exc))
            continue
        key = probe_key(state, system, rom_sha1)
        verdict, _ = _known(state, system, key, lambda: _ships(Path(path), state))  # noqa: B023 (called at once)
        if verdict is None:
            keys[name] = key
            plans[name] = (name, os.fspath(path), max(frames, PROBE_FRAMES), PROBE_INPUT_FRAMES)
        elif verdict.safe:
            plans[name] = (name, os.fspath(path), frames, 0)
        else:
            results[name] = ChildResult(name, os.fspath(path), error=f"the core cannot run the state: {verdict.reason}")
    todo = list(plans)
    while todo:
        done, blamed, failure = run_child(system, rom, [plans[n] for n in todo], fields=fields, timeout=timeout)
        results.update(done)
        if blamed is None and failure:  # the child failed before any state: it says nothing of them, keep nothing
            results.update({n: ChildResult(n, plans[n][1], error=failure.reason) for n in todo})
            keys = {n: key for n, key in keys.items() if n not in todo}
        elif blamed is not None and failure:
            results[blamed] = ChildResult(blamed, plans[blamed][1], error=failure.reason)
            if not failure.lasting:  # a hang on a loaded machine: probed again next time
                keys.pop(blamed, None)
        todo = [n for n in todo if n not in results]
    for name, key in keys.items():
        result = results[name]
        _remember(key, ProbeVerdict(True) if result.loaded else ProbeVerdict(False, result.error))
    return {name: results[name] for name in files}


# --- One state's verdict -------------------------------------------------------------------------


PROBE_VERSION = 2
"""The probe whose verdicts count. Version 1 read its child's answers from the stdout the core prints on, so a
state could write its own "safe" (issue 42): its verdicts are under other keys, and every state is probed again."""


def probe_key(state: bytes, system: str, rom_sha1: str) -> str:
    """The cache key of a probe: SHA-256 of the probe's version, the system, the ROM's SHA-1 and the state."""
    import hashlib

    digest = hashlib.sha256(f"probe {PROBE_VERSION}\0{system}\0{rom_sha1}\0".encode())
    digest.update(state)
    return digest.hexdigest()


def probe_state(
    state: bytes, system: str | System, rom: str | os.PathLike[str], *, frames: int = PROBE_FRAMES,
    input_frames: int = PROBE_INPUT_FRAMES, timeout: float | None = None,
) -> ProbeVerdict:
    """Load ``state`` on ``rom`` in a child process, run, load again, run under input; report how it ended.

    This is not cached: see :func:`vet_state`.

    Args:
        state: The serialized state (uncompressed).
        system: The system (a name or descriptor).
        rom: The ROM to load it on.
        frames: Idle frames to run after the first load.
        input_frames: Frames of random input to run after the second.
        timeout: Seconds before the child counts as hung, and is killed (by default :data:`PROBE_TIMEOUT`).
    """
    from retrokit.data.states import compress_state

    system = get_system(system).name
    with tempfile.NamedTemporaryFile(prefix="retrokit-probe-", suffix=".state") as tmp:
        tmp.write(compress_state(state))
        tmp.flush()
        results, _, failure = run_child(system, rom, [("state", tmp.name, frames, input_frames)], timeout=timeout)
    if failure:  # how the child ended comes first: a dead or hung child vouches for nothing it answered
        return failure
    result = results.get("state")
    if result is None:
        return ProbeVerdict(False, "the probe stopped before it loaded the state")
    return ProbeVerdict(True) if result.loaded else ProbeVerdict(False, result.error)


PROBES = "state-probes"
"""The data folder's folder of verdicts (:mod:`retrokit.host.verdicts`: never through a link)."""


def _cached(key: str) -> ProbeVerdict | None:
    return kept_verdict(PROBES, key, "a probe's verdict")


def _remember(key: str, verdict: ProbeVerdict) -> None:
    keep_verdict(PROBES, key, verdict)  # a hang's verdict is not lasting: not kept


def remember(state: VettedState, rom_sha1: str) -> None:
    """Note that this machine wrote ``state`` (it came from a core), so loading it from a file again needs no probe.

    Args:
        state: A state a core made (:meth:`~retrokit.host.emulator.Emulator.get_state`) or one already checked.
        rom_sha1: The SHA-1 of the ROM it runs on.
    """
    if not isinstance(state, VettedState):
        raise StateError(f"Expected a checked state (VettedState) to remember as safe; found {type(state).__name__}.")
    _remember(probe_key(state, state.system, rom_sha1), ProbeVerdict(True))


def vet_state(
    state: bytes, system: str | System, rom: str | os.PathLike[str], rom_sha1: str, *, source: str,
    shipped: str | os.PathLike[str] | None = None,
) -> VettedState:
    """Return ``state`` as a :class:`VettedState` once it is known not to crash or hang the core.

    Args:
        state: The serialized state.
        system: The system's name.
        rom: The ROM the state is for.
        rom_sha1: The ROM's SHA-1 (part of the cache key).
        source: What to call the state in the error (its path, or a movie's Core.bin).
        shipped: The ``.state`` file ``state`` was read from: if its bytes are a
            shipped state file's, and it holds exactly ``state``, no probe is needed.

    Raises:
        StateError: The state crashed, hung or was refused in the child.
    """
    system = get_system(system).name
    if isinstance(state, VettedState) and state.system == system:
        return state
    state = bytes(state)
    key = probe_key(state, system, rom_sha1)
    verdict, ships = _known(state, system, key, lambda: shipped is not None and _ships(Path(shipped), state))
    if ships and _cached(key) is None:  # a movie that starts from it (Core.bin) is then known too
        _remember(key, ProbeVerdict(True))
    if verdict is None:
        verdict = probe_state(state, system, rom)
        _remember(key, verdict)
    if not verdict.safe:
        raise _unrunnable(source, system, verdict.reason)
    return _mint(state, system)


def _known(state: bytes, system: str, key: str, ships: Callable[[], bool]) -> tuple[ProbeVerdict | None, bool]:
    """What this machine knows of a state without probing it, in the one order of trust; writes nothing.

    Args:
        state: The serialized state.
        system: The system's name.
        key: The state's :func:`probe_key` on the ROM it is for.
        ships: Whether the state's file is one retrokit or the stable-retro wheel ships (asked only if needed).

    Returns:
        The verdict (``None``: only a probe can tell) and whether it comes from the state being shipped.
    """
    # Before any record or probe: a state the core would map outside its memory crashes or not by the
    # process's layout, so a probe's verdict on it (or an old record of one) proves nothing.
    problem = state_layout_problem(system, state)
    if problem:
        return ProbeVerdict(False, problem), False
    if ships():
        return ProbeVerdict(True), True
    return _cached(key), False


def _unrunnable(source: str, system: str, reason: str) -> StateError:
    return StateError(
        f"{source}: expected a save state the {system} core can run; found one that it cannot: "
        f"{reason}. The file is corrupt or was made by something else; record or copy it again."
    )


def _ships(path: Path, state: bytes) -> bool:
    """Whether the file at ``path`` is a shipped state file (by its SHA-256) and holds exactly ``state``."""
    try:
        with open(path, "rb") as f:
            blob = f.read(MAX_STATE_FILE_SIZE + 1)
    except OSError:
        return False
    if not is_shipped_blob(blob):
        return False
    try:
        return decompress_state(blob) == state
    except StateError:
        return False


# --- The child -----------------------------------------------------------------------------------


def _child_main() -> int:
    """Load the states a request names, one by one; answer one JSON line per state (and one before each).

    The answers go on the channel :mod:`retrokit.host.child` gives (never stdout, which the core prints on).
    """
    import random

    from retrokit.data.states import read_state, state_format
    from retrokit.host.child import answer_channel, read_request
    from retrokit.host.emulator import Emulator
    from retrokit.host.fields import FieldSpec
    from retrokit.host.memory import FieldReader

    request = read_request()  # its limits are set by now (retrokit.host.child)
    answer = answer_channel(request)
    emu = Emulator(request["system"], request["rom"])
    specs = [FieldSpec(f["name"], f["address"], f["type"], f["mask"]) for f in request["fields"]]
    reader = FieldReader([s for s in specs if emu.space.holds(s.address, s.field_type.width)], emu.space)
    idle = [0] * emu.ports
    rng = random.Random(0)
    for name, path, frames, input_frames in request["states"]:
        answer.write(json.dumps({"begin": name}).encode() + b"\n")
        result: dict[str, Any] = {"name": name, "path": path}
        try:
            data = read_state(path)
            problem = state_layout_problem(emu.system.name, data)
            if problem:  # the core would read memory it does not own: a crash here or not is luck
                raise StateError(f"the core cannot run the state: {problem}")
            state = _mint(data, emu.system.name)  # unchecked: finding out whether it is safe is this child's job
            emu.set_state(state)
            result["start"] = reader.read()
            emu.run(idle, 1)  # one frame in: where validate checks the fields' declared ranges
            result["first"] = reader.read()
            emu.run(idle, max(int(frames) - 1, 0))
            result["after"] = reader.read()
            emu.set_state(state)  # every reset() loads the state again: some crash only then
            for _ in range(0, int(input_frames), 10):  # and some only under input
                emu.run([rng.getrandbits(12) for _ in range(emu.ports)], 10)
            # An env's reset(): load, one scratch frame (its first observation), load again. Loading
            # resets the console from the state that ran before, so a load after one frame differs.
            emu.set_state(state)
            emu.run(idle, 1)
            emu.set_state(state)
            emu.get_state()
            result["loaded"] = True
            result["detail"] = f"{state_format(data) or 'no core signature'}, {len(data)} bytes"
        except (RetrokitError, MemoryError) as exc:
            result["error"] = str(exc) if not isinstance(exc, MemoryError) else "the state needs too much memory"
        answer.write(json.dumps(result).encode() + b"\n")
    emu.close()
    return 0


if __name__ == "__main__":
    sys.exit(_child_main())
