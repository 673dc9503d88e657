"""``retrokit cores``: which libretro core each system uses, and where it comes from."""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``cores`` command."""
    parser = subparsers.add_parser(
        "cores",
        help="list which libretro core each system uses, and where it was found",
        description="List each system's libretro core, whether it is patched (built by retrokit build-core, which "
        "skips drawing and sound nobody sees), and where it was found: RETROKIT_CORES, a core built by "
        "retrokit build-core (in the data folder), the stable-retro wheel, or the system's libretro folder.",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """List the systems' cores, and which are patched."""
    from retrokit.errors import CoreNotFoundError
    from retrokit.host.build import RECIPES
    from retrokit.host.buildhint import speedup_text
    from retrokit.host.cores import locate_core
    from retrokit.host.systems import all_systems

    systems = all_systems()
    width = max(len("SYSTEM"), *(len(name) for name in systems))
    core_width = max(len("CORE"), *(len(s.core) for s in systems.values()))
    print(f"{'SYSTEM':<{width}}  {'CORE':<{core_width}}  {'PATCHED':<7}  {'FOUND IN':<14}  PATH")
    for name, system in systems.items():
        try:
            found = locate_core(system.core)
            patched = "yes" if found.origin == "built" else "no"
            where = f"{found.origin:<14}  {found.path}" + (f"  ({found.note})" if found.note else "")
        except CoreNotFoundError:
            patched, where = "no", "missing"
        print(f"{name:<{width}}  {system.core:<{core_width}}  {patched:<7}  {where}")
    gains = {core: [f"{s.name} envs step {speedup_text(s)}, measured on {s.build_measured}"
                    for s in systems.values() if s.core == core and speedup_text(s)] for core in RECIPES}
    buildable = ", ".join(core + (f" ({'; '.join(gains[core])})" if gains[core] else "") for core in RECIPES)
    print(f"PATCHED: built by retrokit build-core, which skips work on the frames an env does not show. "
          f"Cores it can build: {buildable} (retrokit build-core CORE).")
    return 0


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit cores                     # each system's core, and where it was found",
]
