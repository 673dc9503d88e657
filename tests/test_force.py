"""One word for "replace what is there" in every command (--force), and one place that says a file is in the way.

The atomic writer in paths.py raises FileConflictError itself, with where and how
to fix it; no caller re-words a FileExistsError.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from retrokit import paths
from retrokit.cli import build_parser, main
from retrokit.errors import FileConflictError

PACKAGE = Path(__file__).resolve().parent.parent / "retrokit"


def parsers(parser: argparse.ArgumentParser, name: str = "retrokit") -> list[tuple[str, argparse.ArgumentParser]]:
    """Every parser of the command line, with its command line, sub-commands included."""
    found = [(name, parser)]
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub, child in action.choices.items():
                found += parsers(child, f"{name} {sub}")
    return found


ALL = parsers(build_parser())


@pytest.mark.parametrize("name, parser", ALL, ids=[name for name, _ in ALL])
def test_no_command_offers_another_word_than_force(name: str, parser: argparse.ArgumentParser) -> None:
    assert "--overwrite" not in parser.format_help()
    options = {option for action in parser._actions for option in action.option_strings}
    assert not options & {"--replace", "--clobber", "-f"}
    if "--overwrite" in options:  # the old word still parses, as a hidden alias of --force
        (overwrite,) = [a for a in parser._actions if "--overwrite" in a.option_strings]
        assert overwrite.dest == "force" and overwrite.help == argparse.SUPPRESS


def test_the_commands_that_said_overwrite_say_force() -> None:
    said = {name for name, parser in ALL for a in parser._actions if "--overwrite" in a.option_strings}
    assert said == {"retrokit convert", "retrokit import", "retrokit playback", "retrokit ramsearch screenshot"}
    forced = {name for name, parser in ALL for a in parser._actions if "--force" in a.option_strings}
    assert said < forced


def test_no_caller_rewords_a_file_exists_error() -> None:
    catching = [
        p.relative_to(PACKAGE).as_posix()
        for p in PACKAGE.rglob("*.py")
        if "_games" not in p.parts and re.search(r"except \(?[\w, ]*FileExistsError", p.read_text())
    ]
    # paths.py is the writer itself (the recorder claims a free name through it, taking the next on its error)
    assert catching == ["paths.py"]


def test_the_writer_names_the_file_and_the_fix(tmp_path: Path) -> None:
    mine = tmp_path / "mine.bin"
    mine.write_bytes(b"mine")
    with pytest.raises(FileConflictError) as error:
        paths.atomic_write(mine, b"theirs")
    message = str(error.value)
    assert repr(str(mine)) in message and "left as it is" in message and "--force" in message
    assert isinstance(error.value, FileExistsError)  # still what Python code catches
    with pytest.raises(FileConflictError, match="Delete it first"):
        paths.atomic_write(mine, b"theirs", hint="Delete it first.")
    assert mine.read_bytes() == b"mine" and [p.name for p in tmp_path.iterdir()] == ["mine.bin"]  # no temp file left
    paths.atomic_write(mine, b"theirs", overwrite=True)
    assert mine.read_bytes() == b"theirs"


def test_a_streamed_write_is_refused_before_its_work(tmp_path: Path) -> None:
    mine = tmp_path / "long.gif"
    mine.write_bytes(b"mine")
    ran = []
    with pytest.raises(FileConflictError), paths.atomic_output(mine) as stream:
        ran.append(stream)
    assert not ran and mine.read_bytes() == b"mine"


def test_a_dangling_symlink_is_in_the_way_too(tmp_path: Path) -> None:
    (tmp_path / "link").symlink_to(tmp_path / "nowhere")
    with pytest.raises(FileConflictError):
        paths.atomic_write(tmp_path / "link", b"x")
    assert not (tmp_path / "nowhere").exists()


def test_playback_says_force(tmp_path: Path, capsys) -> None:
    movie = PACKAGE.parent / "games" / "Dasher-Genesis" / "movies" / "Zone1.Act1.bk2"
    out = tmp_path / "out.gif"
    out.write_bytes(b"mine")
    assert main(["playback", str(movie), str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--force" in err and out.read_bytes() == b"mine"
    assert main(["playback", str(movie), str(out), "--force", "--every", "50"]) == 0
    assert out.read_bytes()[:3] == b"GIF"
