"""Building many envs only when they fit in memory: a count is checked against what one env takes.

``make_vec(game, 10**6)`` used to build envs until memory ran out (gigabytes
later), then raise MemoryError. :func:`build_envs` builds the first two, takes
the second's growth of this process as what each further one needs (the first
also pays for one-off costs: the core's loading, imports), and refuses a count
whose total would not fit in the memory available: the system's
(``MemAvailable`` in ``/proc/meminfo``), the cgroup's (``memory.max``), and
the address-space limit (``ulimit -v``).
"""

from __future__ import annotations

import resource
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from retrokit.errors import InvalidArgumentError

#: What an env grows to once it runs (screens, buffers, the batch) over what building it took.
HEADROOM = 1.5
#: Less than any env takes (a Genesis env takes about 10 MiB resident, 20 MiB of address space): a count
#: refused with it is refused before anything is built, even before a list of that many env functions.
MIN_ENV_BYTES = 2**20
_CGROUP = Path("/sys/fs/cgroup")


def _status_kb(key: str) -> int | None:
    """A ``kB`` value of ``/proc/self/status`` (``VmRSS``, ``VmSize``), or ``None`` where there is none."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith(key + ":"):
                    return int(line.split()[1])
    except (OSError, ValueError):
        pass
    return None


def usage() -> tuple[int | None, int | None]:
    """This process's resident memory and address space, in bytes (``None`` where unknown)."""
    rss, size = _status_kb("VmRSS"), _status_kb("VmSize")
    return (None if rss is None else rss * 1024), (None if size is None else size * 1024)


def available_memory() -> int | None:
    """The bytes of memory more envs could take: the least of the system's and the cgroup's headroom."""
    found = []
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    found.append(int(line.split()[1]) * 1024)
    except (OSError, ValueError):
        pass
    try:
        limit = (_CGROUP / "memory.max").read_text().strip()
        if limit != "max":
            found.append(int(limit) - int((_CGROUP / "memory.current").read_text()))
    except (OSError, ValueError):
        pass
    return min(found) if found else None


def available_address_space() -> int | None:
    """The bytes of address space this process may still map (``ulimit -v``), or ``None`` without a limit."""
    limit = resource.getrlimit(resource.RLIMIT_AS)[0]
    size = usage()[1]
    return None if limit == resource.RLIM_INFINITY or size is None else limit - size


def _gib(size: float) -> str:
    return f"{size / 2**30:,.1f} GiB" if size >= 2**30 else f"{size / 2**20:,.0f} MiB"


def check_fits(count: int, each: tuple[int, int], *, at_least: bool = False) -> None:
    """Refuse ``count`` more envs when each takes ``each`` (resident bytes, address-space bytes).

    Args:
        count: How many more envs are to be built.
        each: What one takes, measured; or, with ``at_least``, a lower bound.
        at_least: ``each`` is a lower bound, not a measure.

    Raises:
        InvalidArgumentError: They would not fit; the message says how many would.
    """
    for needed, room, kind in (
        (each[0], available_memory(), "memory available (MemAvailable, or the cgroup's limit)"),
        (each[1], available_address_space(), "address space left under ulimit -v"),
    ):
        if room is None or needed <= 0 or count * needed * HEADROOM <= room:
            continue
        fit = max(int(room / (needed * HEADROOM)), 0)
        built = 0 if at_least else 2
        raise InvalidArgumentError(
            f"Expected num_envs whose envs fit in memory: each takes {'at least' if at_least else 'about'} "
            f"{_gib(needed)} here, so {count + built:,} need {'over' if at_least else 'about'} "
            f"{_gib(count * needed * HEADROOM)} with room to run; found {_gib(max(room, 0))} of {kind}. "
            + (f"Pass a num_envs of at most {fit + built:,}" if not at_least else "Pass a much smaller num_envs")
            + ", or spread them over processes or machines."
        )


def build_envs(env_fns: Sequence[Callable[[], Any]]) -> list[Any]:
    """Call every env function, refusing (before the third) a count that would not fit in memory.

    Raises:
        InvalidArgumentError: The envs would not fit; those built are closed.
    """
    envs: list[Any] = []
    try:
        for i, fn in enumerate(env_fns):
            before = usage() if i == 1 else None
            envs.append(fn())
            if before is not None and len(env_fns) > 2:
                after = usage()
                if None not in (*before, *after):
                    check_fits(len(env_fns) - 2, (after[0] - before[0], after[1] - before[1]))
    except BaseException:
        for env in envs:
            env.close()
        raise
    return envs
