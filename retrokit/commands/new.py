"""``retrokit new ROM --name NAME-SYSTEM [--system S]``: start a new game from a ROM no game knows."""

from __future__ import annotations

import argparse

from retrokit.commands._common import add_data_dir_option


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``new`` command."""
    parser = subparsers.add_parser(
        "new",
        help="start integrating a game nobody has: a game.yaml in your games folder, and its ROM imported",
        description="Make a new game from a ROM that no known game matches (retrokit import lists those, with "
        "their SHA-1 and likely system). The ROM's system is told from its header (a Genesis ROM says SEGA at "
        "0x100, even as a .bin), else from its size (an Atari 2600 .bin of 2 to 32 KiB), else from its extension, "
        "else from the name's system suffix or --system. The game is made in your games "
        "folder, <data>/games/NAME-SYSTEM/ (every command looks there, and in the folders of $RETROKIT_GAMES), "
        "with a game.yaml holding the system and the ROM's SHA-1 and no fields yet; the ROM is imported into "
        "<data>/roms/NAME-SYSTEM/. The next commands are printed; retrokit docs integrate walks through the rest.",
    )
    parser.add_argument("rom", metavar="ROM", help="the ROM file")
    parser.add_argument("--name", required=True, metavar="NAME-SYSTEM",
                        help="the new game's name: letters, digits and underscores, then the system (Runner-Genesis)")
    parser.add_argument("--system", metavar="S", help="the ROM's system, when its header and extension do not tell it")
    add_data_dir_option(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Make the game; print where it is and what to do next."""
    from retrokit.data.newgame import new_game

    made = new_game(args.rom, args.name, system=args.system, data_dir=args.data_dir)
    name = made.game.name
    print(f"Made {name} ({made.game.system}, told by its {made.told_by}; ROM SHA-1 {made.sha1}):")
    print(f"  game file  {made.folder / 'game.yaml'}")
    print(f"  ROM        {made.rom}")
    print("Next: a first state, saved from a RAM search session (retrokit docs integrate: \"Your own game, from a ROM\"):")
    print(f"  retrokit ramsearch new {name}    # from power-on")
    start = made.game.system.start  # START, a PC Engine's RUN, a 2600's RESET switch
    print(f"  retrokit ramsearch run --script '_*20 {start}*2 _*98'    # for example: play on to the first level")
    print("  retrokit ramsearch savestate Level1 --default")
    print(f"then: retrokit ramsearch new {name} --state Level1 --force    # find its fields (retrokit docs ramsearch)")
    print(f"      retrokit validate {name}")
    return 0


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit new ~/roms/runner.bin --name Runner-Genesis",
    "retrokit new ~/roms/mystery.rom --name Mystery-Nes --system Nes   # header and extension tell nothing",
]
