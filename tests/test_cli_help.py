"""Every command's ``--help`` ends with examples, and every example is a command line the parser takes."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from retrokit import cli
from retrokit.commands import command_modules


def walk(parser: cli.CommandParser, path: tuple[str, ...] = ()) -> Iterator[tuple[tuple[str, ...], cli.CommandParser]]:
    """Every parser of the command line with the words that reach it, the top level first."""
    yield path, parser
    seen: set[int] = set()
    for name, sub in parser.subcommands.items():
        if id(sub) not in seen:  # an alias names the same parser again
            seen.add(id(sub))
            yield from walk(sub, (*path, name))


PARSER = cli.build_parser()
COMMANDS = list(walk(PARSER))
EXAMPLES = [(module.__name__.rsplit(".", 1)[1], example) for module in command_modules()
            for example in getattr(module, "EXAMPLES", ())] + [("cli", example) for example in cli.EXAMPLES]


def test_the_walk_reaches_commands_and_subcommands() -> None:
    paths = {" ".join(path) for path, _ in COMMANDS}
    assert {"", "games", "ramsearch", "ramsearch filter", "ramsearch shell"} <= paths


@pytest.mark.parametrize(("path", "parser"), COMMANDS, ids=[" ".join(("retrokit", *p)) for p, _ in COMMANDS])
def test_help_ends_with_examples_of_this_command(path: tuple[str, ...], parser: cli.CommandParser) -> None:
    where = " ".join(("retrokit", *path))
    assert parser.examples, (
        f"{where} --help shows no example: add a full command line starting with '{where}' to EXAMPLES "
        "in its module under retrokit/commands/"
    )
    assert parser.format_help().endswith("\nexamples:\n" + "".join(f"  {e}\n" for e in parser.examples))
    if path:  # the top level's examples are where to start; the others run this command or a subcommand
        assert all(cli.example_words(e)[: len(path)] == list(path) for e in parser.examples)


@pytest.mark.parametrize(("module", "example"), EXAMPLES, ids=[f"{m}: {e.split('#')[0].strip()}" for m, e in EXAMPLES])
def test_every_example_parses_with_the_real_parser(module: str, example: str) -> None:
    assert example.startswith("retrokit "), "an example is a full command line"
    try:
        args = PARSER.parse_args(cli.example_words(example))
    except SystemExit as exc:  # argparse printed why
        pytest.fail(f"{example!r} (in {module}) does not parse: exit status {exc.code}")
    assert callable(args.run)


def test_top_level_help_says_where_to_start_and_where_the_docs_are(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "Start with 'retrokit demo'" in out and "retrokit docs TOPIC" in out and "docs/*.md" in out
    assert "\nexamples:\n  retrokit demo " in out


def test_a_subcommand_help_prints_its_examples(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["ramsearch", "filter", "--help"]) == 0
    out = capsys.readouterr().out
    assert out.rstrip().splitlines()[-1].startswith("  retrokit ramsearch filter ")
