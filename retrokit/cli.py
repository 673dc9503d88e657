"""The ``retrokit`` command line: ``retrokit <command> [options]``.

The commands live in :mod:`retrokit.commands`, one module each. Errors that
retrokit raises on purpose (:class:`~retrokit.errors.RetrokitError`) are printed
as one message, without a traceback, and exit with status 2; so, as a last
resort, is a file-system error that escaped them.

Every command's ``--help`` ends with examples: each command module lists full
command lines in ``EXAMPLES``, and :func:`build_parser` shows each one at the
end of the help of the (sub)command it runs, and of that command's parent (so
``retrokit ramsearch --help`` shows its subcommands' examples too). A module
whose parser shows them in its own epilog may give that text as ``EXAMPLES``
instead: its lines that start with ``retrokit`` are the examples. A test
(tests/test_cli_teaches.py) walks every (sub)command and fails if one has no
example, or if an example does not parse.
"""

from __future__ import annotations

import argparse
import os
import re
import shlex
import sys
from collections.abc import Iterable, Sequence
from typing import NoReturn

from retrokit import __version__
from retrokit.commands import command_modules
from retrokit.errors import RetrokitError, did_you_mean

ERROR_STATUS = 2

#: The top level's own examples: where a new user starts.
EXAMPLES = [
    "retrokit demo                      # start here: JERK against random on the bundled Dasher benchmark",
    "retrokit games                     # the known games, their states, and whether their ROM is here",
    "retrokit import ~/roms             # copy the ROMs of known games from a folder or .zip",
    "retrokit evaluate --benchmark dasher --agent random --out runs/random",
    "retrokit docs                      # the guides (docs/*.md); print one with retrokit docs TOPIC",
]


class CommandParser(argparse.ArgumentParser):
    """An argument parser whose help ends with examples; every parser of the command line is one.

    Attributes:
        examples: Full command lines, shown at the end of ``--help``.
        subcommands: The subcommands' parsers by name (empty for a command without any).
    """

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.examples: list[str] = []
        self.subcommands: dict[str, CommandParser] = {}

    def add_subparsers(self, **kwargs) -> argparse._SubParsersAction:
        """Add subcommands as argparse does (they are CommandParsers too), and keep their parsers."""
        action = super().add_subparsers(**kwargs)
        self.subcommands = action.choices  # the same dict, filled as subcommands are added
        return action

    def error(self, message: str) -> NoReturn:
        """Print a usage error and exit; an invalid choice (a misspelled command) gets a did-you-mean."""
        found = re.search(r"argument (\S+): invalid choice: '([^']*)' \(choose from (.*)\)$", message)
        if found:
            what, given, listed = found.groups()
            choices = re.findall(r"'([^']*)'", listed)
            message = (
                f"Expected {what} to be one of {', '.join(choices)}; got {given!r}."
                + did_you_mean(given, choices) + f" See: {self.prog} --help."
            )
        super().error(message)

    def format_help(self) -> str:
        """The help, ending with the examples (argparse's epilog would wrap them into one paragraph).

        Examples the parser's own epilog already shows are not shown twice.
        """
        text = super().format_help()
        shown = [example for example in self.examples if example not in (self.epilog or "")]
        if not shown:
            return text
        return text + "\nexamples:\n" + "".join(f"  {example}\n" for example in shown)


def example_words(example: str) -> list[str]:
    """The words of an example command line after ``retrokit``, as a shell splits them (``# ...`` is a comment)."""
    words = shlex.split(example, comments=True)
    return words[1:] if words[:1] == ["retrokit"] else words


def add_examples(root: CommandParser, examples: Iterable[str] | str) -> None:
    """Show each example in the help of the command it runs and of that command's parent (but the top level's).

    ``examples`` is a list of command lines, or the text of an epilog in which
    they are the lines that start with ``retrokit``.
    """
    if isinstance(examples, str):
        examples = [line.strip() for line in examples.splitlines() if line.strip().startswith("retrokit ")]
    for example in examples:
        chain = [root]
        for word in example_words(example):
            sub = chain[-1].subcommands.get(word)
            if sub is None:
                break
            chain.append(sub)
        for parser in chain[-2:] if len(chain) > 2 else chain[-1:]:
            parser.examples.append(example)


def build_parser() -> CommandParser:
    """Return the argument parser, with a subparser for every command module and each module's ``EXAMPLES``."""
    parser = CommandParser(
        prog="retrokit",
        description="Emulated console games as reinforcement-learning environments, and the tools to integrate "
        "them. Start with 'retrokit demo' (no ROM needed): it evaluates two agents on the bundled Dasher "
        "benchmark and writes a report. The guides: 'retrokit docs TOPIC', or docs/*.md in the source; "
        "each command's --help ends with examples.",
    )
    parser.add_argument("--version", action="version", version=f"retrokit {__version__}")
    subparsers = parser.add_subparsers(title="commands", metavar="COMMAND")
    for module in command_modules():
        module.register(subparsers)
        add_examples(parser, getattr(module, "EXAMPLES", ()))
    parser.examples.extend(EXAMPLES)  # the top level's own, not its commands'
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
