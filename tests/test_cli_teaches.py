"""The command line teaches itself: every ``--help`` ends with examples that parse; listings have headers,
arguments are named as the help's text names them, and what the user cannot fix by installing is said first."""

from __future__ import annotations

import sys
from collections.abc import Iterator

import pytest

from retrokit import cli


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
# Each example once, with the command whose help shows it first (a subcommand's shows in its parent's too).
EXAMPLES = list({e: (" ".join(("retrokit", *p)), e) for p, parser in reversed(COMMANDS) for e in parser.examples}.values())


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
    last = [line.strip() for line in parser.format_help().splitlines() if line.strip()][-len(parser.examples) :]
    assert last == parser.examples, f"{where} --help does not end with its examples"
    if path:  # the top level's examples are where to start; the others run this command or a subcommand
        assert all(cli.example_words(e)[: len(path)] == list(path) for e in parser.examples)


@pytest.mark.parametrize(("command", "example"), EXAMPLES, ids=[f"{c}: {e.split('#')[0].strip()}" for c, e in EXAMPLES])
def test_every_example_parses_with_the_real_parser(command: str, example: str) -> None:
    assert example.startswith("retrokit "), "an example is a full command line"
    try:
        args = PARSER.parse_args(cli.example_words(example))
    except SystemExit as exc:  # argparse printed why
        pytest.fail(f"{example!r} (shown by {command} --help) does not parse: exit status {exc.code}")
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


# --- listings, names and the order of checks ------------------------------------------------------


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    status = cli.main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_cores_prints_a_header_row_over_aligned_columns(capsys):
    status, out, _ = run(capsys, "cores")
    assert status == 0
    header, first = out.splitlines()[:2]
    assert header.split() == ["SYSTEM", "CORE", "PATCHED", "FOUND", "IN", "PATH"]
    assert first.index(first.split()[1]) == header.index("CORE")  # the columns line up under their names
    assert first.index(first.split()[2], header.index("CORE")) == header.index("PATCHED")


def test_convert_names_its_positionals_as_its_text_does(capsys):
    status, out, _ = run(capsys, "convert", "--help")
    text = " ".join(out.split())  # argparse wraps lines where the terminal width says
    assert status == 0
    assert "SCENARIO.json [OUT]" in text and "Without OUT," in text and "a Gym Retro scenario.json" in text


@pytest.mark.parametrize(
    ("game", "expected"),
    [("SonicTheHedgehog-Genesis", "Expected the ROM of SonicTheHedgehog-Genesis"), ("Dasher-Genesis", "Expected pygame")],
    ids=["rom-missing-is-said-first", "then-pygame"],
)
def test_play_without_pygame_checks_the_rom_first(capsys, monkeypatch, tmp_path, game, expected):
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path))  # nothing imported: Dasher's ROM ships in games/
    monkeypatch.setitem(sys.modules, "pygame", None)  # `import pygame` raises ImportError
    status, out, err = run(capsys, "play", game)
    assert status == 2 and out == ""
    assert err.startswith(f"retrokit: error: {expected}") and "Traceback" not in err


def test_play_without_pygame_names_an_unknown_state_first(capsys, monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "pygame", None)
    status, _, err = run(capsys, "play", "Dasher-Genesis", "--state", "Zone9.Act1")
    assert status == 2 and "Zone9.Act1" in err and "pygame" not in err


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        pytest.param(["gams"], "got 'gams'. Did you mean 'games'? See: retrokit --help.", id="command-typo"),
        pytest.param(["ramsearch", "sav"], "Did you mean 'save'? See: retrokit ramsearch --help.", id="subcommand-typo"),
        pytest.param(
            ["integrate", "Airstriker-Genesis", "Level9"],
            "found no state 'Level9' (its states: Level1), and no recipe", id="integrate-unknown-state",
        ),
    ],
)
def test_a_misspelled_name_gets_one_line_that_teaches(argv, expected, capsys) -> None:
    status = cli.main(argv)
    err = capsys.readouterr().err
    assert status == 2 and expected in err, err
    assert err.count("\n") <= 2, err  # the usage line at most, and the message


def test_a_game_name_error_is_one_short_line_and_any_case_finds_the_game() -> None:
    import retrokit
    from retrokit.errors import GameNotFoundError

    with pytest.raises(GameNotFoundError) as error:
        retrokit.make("Airstrikr-Genesis")
    message = str(error.value)
    assert "site-packages" not in message and len(message) < 250, message
    assert "Did you mean 'Airstriker-Genesis'?" in message and "retrokit games" in message
    env = retrokit.make("airstriker-genesis")  # as `retrokit games airstriker-genesis` finds it
    assert env.game.name == "Airstriker-Genesis"
    env.close()
