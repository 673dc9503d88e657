"""``retrokit build-core CORE``: build a core from stable-retro's source with retrokit's patch."""

from __future__ import annotations

import argparse
import sys


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``build-core`` command."""
    parser = subparsers.add_parser(
        "build-core",
        help="build a faster core from stable-retro's source (needs a C compiler, make and the package index)",
        description="Fetch the source package (sdist) of the installed stable-retro version from the package "
        "index with pip, unpack only the core's source, apply retrokit's patch, build it with the flags "
        "stable-retro's wheel uses, and install it into the data folder, where retrokit uses it instead of the "
        "wheel's (the data folder is $RETROKIT_DATA, else $XDG_DATA_HOME/retrokit, else ~/.local/share/retrokit). "
        "Needs a C compiler (cc, or $CC; stella needs a C++ one too), make, and network access to the package "
        "index. The patched genesis_plus_gx skips drawing the frames an env does not show, and their sound; the "
        "patched stella skips converting them; the patched gambatte skips making and resampling the sound nobody "
        "hears; the patched snes9x and mednafen_pce_fast draw no unseen frame and the patched fceumm converts none "
        "(retrokit docs cores).",
    )
    parser.add_argument("core", metavar="CORE", help="the core to build: genesis_plus_gx, stella, gambatte, snes9x, fceumm or mednafen_pce_fast")
    parser.add_argument("--stable-retro", metavar="VERSION", dest="version",
                        help="build from this stable-retro version's source (default: the installed one; "
                        "retrokit uses a built core only while it matches the installed version)")
    parser.add_argument("--index-url", metavar="URL", help="the package index to fetch from (default: pip's)")
    parser.add_argument("--sdist", metavar="FILE", help="a stable-retro sdist already downloaded, instead of fetching")
    parser.add_argument("--force", action="store_true",
                        help="build again even if built, and replace a core in the data folder that retrokit did not build")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Build and install the core, showing progress."""
    from pathlib import Path

    from tqdm import tqdm

    from retrokit.host.build import build_core

    bar: list[tqdm] = []
    logged: dict[str, int] = {}  # when stderr is a log, not a terminal: the last quarter of each step printed

    def step(message: str) -> None:
        while bar:
            bar.pop().close()
        print(message, file=sys.stderr, flush=True)

    def progress(what: str, done: int, total: int) -> None:
        if not sys.stderr.isatty():
            quarter = 4 * done // total if total else 0
            if quarter > logged.get(what, 0):
                logged[what] = quarter
                print(f"  {what}: {25 * quarter}%", file=sys.stderr, flush=True)
            return
        if not bar:
            scale = what == "download"
            bar.append(tqdm(total=total or None, unit="B" if scale else " files", unit_scale=scale,
                            leave=False, desc=what, file=sys.stderr))
        bar[0].update(done - bar[0].n)

    try:
        path = build_core(
            args.core,
            version=args.version,
            index_url=args.index_url,
            sdist=Path(args.sdist) if args.sdist else None,
            force=args.force,
            progress=progress,
            step=step,
        )
    finally:
        while bar:  # an error message starts on a line of its own
            bar.pop().close()
    print(path)
    return 0


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit build-core genesis_plus_gx                 # fetch stable-retro's source with pip, build, install",
    "retrokit build-core genesis_plus_gx --sdist stable_retro-1.0.1.tar.gz   # from a downloaded sdist, offline",
    "retrokit build-core genesis_plus_gx --index-url https://pypi.example.org/simple --force",
    "retrokit build-core stella                          # the Atari 2600's core, which skips converting unseen frames",
    "retrokit build-core gambatte                        # the Game Boy's core, which skips the sound nobody hears",
]
