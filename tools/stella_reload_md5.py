#!/usr/bin/env python3
"""The ROMs whose Atari 2600 state loads must reload the game, from stella's own properties, against systems.yaml.

stella makes each port's controller from the ROM's entry in its properties
(``DefProps.hxx``, keyed by the ROM's MD5; ``Controller.Left`` and
``Controller.Right``). Joysticks, keyboards, Booster Grips and Genesis pads
set their pins from each frame's buttons alone; every other kind (paddles,
driving controllers, trackballs and mice, the MindLink, the CompuMate, KidVid,
AtariVox, SaveKey) keeps state of its own that no state saves. This reads
``DefProps.hxx`` from a stable-retro sdist (only that member), lists the MD5s
of the ROMs given such a controller, and compares them with
``reload_only_for.md5`` in ``retrokit/host/systems.yaml``.

Usage: python tools/stella_reload_md5.py stable_retro-1.0.1.tar.gz [--print]
"""

from __future__ import annotations

import argparse
import re
import sys
import tarfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
STATELESS = {"", "JOYSTICK", "KEYBOARD", "KEYPAD", "GENESIS", "BOOSTERGRIP"}
MD5, LEFT, RIGHT = 0, 12, 13  # the columns of DefProps: Props.hxx's PropertyType order


def stateful_md5s(sdist: Path) -> set[str]:
    """The MD5s whose properties give either port a controller that keeps state of its own."""
    with tarfile.open(sdist) as tar:
        member = next(m for m in tar.getmembers() if m.name.endswith("cores/atari2600/stella/src/emucore/DefProps.hxx"))
        text = tar.extractfile(member).read().decode("latin-1")  # type: ignore[union-attr]
    found = set()
    for row in re.findall(r"^  \{ (.*) \},?$", text, flags=re.MULTILINE):
        fields = re.findall(r'"((?:[^"\\]|\\.)*)"', row)
        if fields[LEFT].upper() not in STATELESS or fields[RIGHT].upper() not in STATELESS:
            found.add(fields[MD5].lower())
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sdist", type=Path)
    parser.add_argument("--print", action="store_true", help="print the MD5s, one a line")
    args = parser.parse_args()
    sys.path.insert(0, str(REPO))
    from retrokit.host.systems import get_system

    found, listed = stateful_md5s(args.sdist), get_system("Atari2600").reload_md5
    if args.print:
        print("\n".join(sorted(found)))
    print(f"{len(found)} ROMs in stella's properties keep controller state; systems.yaml lists {len(listed)}; "
          f"missing there: {len(found - listed)}, extra: {len(listed - found)}", file=sys.stderr)
    return 0 if found == listed else 1


if __name__ == "__main__":
    sys.exit(main())
