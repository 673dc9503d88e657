"""The subcommands of the ``retrokit`` command line, one module each.

Each module in this package is a command. It defines::

    def register(subparsers: argparse._SubParsersAction) -> None:
        parser = subparsers.add_parser("name", help="one line", description="...")
        parser.add_argument(...)
        parser.set_defaults(run=run)

    def run(args: argparse.Namespace) -> int:
        ...  # return the exit status; raise RetrokitError for a clean error message

    EXAMPLES = [  # full command lines, shown at the end of --help; tests/test_cli_teaches.py parses each
        "retrokit name ARG --option VALUE      # what this does (an optional comment)",
        "retrokit name sub ARG                  # and one at least for every subcommand",
    ]

Modules are found automatically (:func:`command_modules`), so adding a command
means adding a module, nothing else. A module should import heavy things
(emulators, numpy) inside ``run``, so that ``retrokit --help`` stays fast.
Modules whose names start with ``_`` are helpers, not commands.
"""

from __future__ import annotations

import importlib
import pkgutil
from types import ModuleType


def command_modules() -> list[ModuleType]:
    """Import and return every command module of this package, sorted by module name."""
    names = sorted(info.name for info in pkgutil.iter_modules(__path__) if not info.name.startswith("_"))
    return [importlib.import_module(f"{__name__}.{name}") for name in names]
