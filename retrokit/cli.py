"""The ``retrokit`` command line: ``retrokit <command> [options]``.

The commands live in :mod:`retrokit.commands`, one module each. Errors that
retrokit raises on purpose (:class:`~retrokit.errors.RetrokitError`) are printed
as one message, without a traceback, and exit with status 2; so, as a last
resort, is a file-system error that escaped them.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from retrokit import __version__
from retrokit.commands import command_modules
from retrokit.errors import RetrokitError

ERROR_STATUS = 2


def build_parser() -> argparse.ArgumentParser:
    """Return the argument parser, with a subparser for every command module."""
    parser = argparse.ArgumentParser(
        prog="retrokit",
        description="Emulated console games as reinforcement-learning environments, and the tools to integrate them.",
    )
    parser.add_argument("--version", action="version", version=f"retrokit {__version__}")
    subparsers = parser.add_subparsers(title="commands", metavar="COMMAND")
    for module in command_modules():
        module.register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line with ``argv`` (by default ``sys.argv[1:]``); return the exit status."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a usage error (already printed)
        return exc.code if isinstance(exc.code, int) else ERROR_STATUS
    if not hasattr(args, "run"):
        parser.print_help(sys.stderr)
        return ERROR_STATUS
    try:
        return int(args.run(args) or 0)
    except RetrokitError as exc:
        print(f"retrokit: error: {exc}", file=sys.stderr)
        return ERROR_STATUS
    except BrokenPipeError:
        # Whoever read the output stopped (`retrokit games | head`): end quietly, as other
        # command-line tools do. Point stdout at /dev/null so that flushing it at exit
        # does not raise a second time.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except OSError as exc:  # the last resort (file code raises RetrokitError); after BrokenPipeError, an OSError
        where = f" ({exc.filename})" if exc.filename else ""
        print(f"retrokit: error: a file operation failed{where}: {exc.strerror or exc}.", file=sys.stderr)
        return ERROR_STATUS
    except KeyboardInterrupt:
        print("retrokit: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
