"""The core probe's child: ``python -m retrokit.host.coreprobe``, run by :func:`retrokit.host.corecheck.probe_core`.

It reads ``{"system": ..., "rom": ..., "core": ...}`` as JSON on its stdin,
opens an emulator with the core and the ROM, and runs
:data:`~retrokit.host.corecheck.PROBE_FRAMES` frames. It exits 0, or
:data:`~retrokit.host.corecheck.REFUSED` when retrokit refused the core with
its own error (printed on stderr); a damaged core ends it by a signal instead.
It lives apart from :mod:`retrokit.host.corecheck` because it opens an
emulator, and the emulator vets its core through corecheck.
"""

from __future__ import annotations

import sys
from pathlib import Path

from retrokit.errors import RetrokitError
from retrokit.host.child import read_request
from retrokit.host.corecheck import PROBE_FRAMES, REFUSED, mark_probing
from retrokit.host.emulator import Emulator


def main() -> int:
    """Open the emulator with the request's core, run the frames; exit 0, or REFUSED on retrokit's error."""
    request = read_request()  # ends it if the process that asked is killed
    system, rom, core = str(request["system"]), str(request["rom"]), str(request["core"])
    mark_probing(Path(core))  # this process is the probe: it loads the core unvetted
    try:
        with Emulator(system, rom, core_path=core) as emulator:
            emulator.run(0, PROBE_FRAMES)
    except RetrokitError as exc:
        print(exc, file=sys.stderr)
        return REFUSED
    return 0


if __name__ == "__main__":
    sys.exit(main())
