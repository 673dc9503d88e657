"""``retrokit playback MOVIE.bk2 OUT [--every N] [--force]``: replay a movie into images or a video."""

from __future__ import annotations

import argparse

from retrokit.commands._common import add_force_option


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``playback`` command."""
    parser = subparsers.add_parser(
        "playback",
        help="replay a .bk2 movie into PNG frames, a GIF or an MP4",
        description="Replay a .bk2 movie (recorded by retrokit or stable-retro) on its game's ROM, "
        "and write the screens: into a folder as frame_000000.png, ... (numbered by movie frame), "
        "or into OUT.gif (30 frames a second at most), or OUT.mp4 (needs: pip install 'retrokit-rl[video]'). "
        "A progress bar shows on standard error.",
    )
    parser.add_argument("movie", metavar="MOVIE.bk2", help="the movie to replay")
    parser.add_argument("out", metavar="OUT", help="a folder for PNG frames, or a .gif or .mp4 file")
    parser.add_argument("--every", type=int, default=1, metavar="N", help="keep one frame in N (default: 1, all)")
    add_force_option(parser, "replace an existing output file or frames")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Replay the movie and write its screens."""
    from retrokit.movie import export

    count = export(args.movie, args.out, every=args.every, overwrite=args.force, progress=True)
    print(f"Wrote {count} frame{'s' * (count != 1)} of {args.movie} to {args.out}.")
    return 0


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit playback Mine-000000.bk2 mine.gif          # an animated GIF",
    "retrokit playback Mine-000000.bk2 frames --every 4  # one PNG in 4 into the folder frames",
]
