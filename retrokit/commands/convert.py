"""``retrokit convert SCENARIO.json [OUT]``: a Gym Retro scenario as retrokit scenario YAML."""

from __future__ import annotations

import argparse
from pathlib import Path

from retrokit.commands._common import add_force_option


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``convert`` command."""
    parser = subparsers.add_parser(
        "convert",
        help="convert a Gym Retro scenario.json to retrokit scenario YAML",
        description="Write a Gym Retro scenario.json as retrokit scenario YAML, with the same rewards and done "
        "condition (Lua scripts cannot be converted). Without OUT, the YAML goes to standard output. "
        "An existing OUT is never replaced unless --force.",
    )
    parser.add_argument("source", type=Path, metavar="SCENARIO.json", help="the Gym Retro scenario to convert")
    parser.add_argument("out", type=Path, nargs="?", metavar="OUT", help="the .yaml to write")
    add_force_option(parser, "replace OUT if it exists")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Convert, then print or write the YAML."""
    from retrokit.dsl import convert_scenario_json
    from retrokit.paths import atomic_write, require_regular_file

    if args.source.exists():  # a FIFO would block, a device never end
        require_regular_file(args.source, "a Gym Retro scenario.json")
    text = convert_scenario_json(args.source)
    if args.out is None:
        print(text, end="")
        return 0
    atomic_write(args.out, text.encode("utf-8"), overwrite=args.force)
    print(f"wrote {args.out}")
    return 0


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit convert scenario.json scenario.yaml      # a Gym Retro scenario as retrokit YAML",
    "retrokit convert scenario.json                    # print the YAML instead",
]
