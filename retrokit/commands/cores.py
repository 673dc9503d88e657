"""``retrokit cores``: which libretro core each system uses, and where it comes from."""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``cores`` command."""
    parser = subparsers.add_parser(
        "cores",
        help="list which libretro core each system uses, and where it was found",
        description="List each system's libretro core and where it was found: RETROKIT_CORES, a core built by "
        "retrokit build-core (in the data folder), the stable-retro wheel, or the system's libretro folder.",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """List the systems' cores."""
    from retrokit.errors import CoreNotFoundError
    from retrokit.host.build import RECIPES
    from retrokit.host.cores import locate_core
    from retrokit.host.systems import all_systems

    systems = all_systems()
    width = max(len("SYSTEM"), *(len(name) for name in systems))
    core_width = max(len("CORE"), *(len(s.core) for s in systems.values()))
    print(f"{'SYSTEM':<{width}}  {'CORE':<{core_width}}  {'FOUND IN':<14}  PATH")
    for name, system in systems.items():
        try:
            found = locate_core(system.core)
            where = f"{found.origin:<14}  {found.path}" + (f"  ({found.note})" if found.note else "")
        except CoreNotFoundError:
            where = "missing"
        print(f"{name:<{width}}  {system.core:<{core_width}}  {where}")
    buildable = ", ".join(RECIPES)
    print(f"Cores retrokit can build, to skip drawing the frames an env does not show: {buildable} "
          "(retrokit build-core CORE).")
    return 0


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit cores                     # each system's core, and where it was found",
]
