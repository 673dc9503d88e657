"""Running docs/integrate.md's walkthrough, "Your own game, from a ROM", as written.

The section's blocks run in order in one working folder, with a fresh data
folder shown in the text as ``~/.local/share/retrokit``:

- a ``python`` block is executed (it builds the header-patched ROM);
- a ``yaml`` block whose first line is ``# file: PATH`` is that file's text,
  written by hand; ``# append to: PATH`` is text added at its end;
- any other block is shown, not run (the test checks the ``game.yaml`` the
  commands wrote against its block);
- a ``console`` block holds ``$ retrokit ...`` commands, each followed by
  what it prints (standard output, then any ``retrokit: error:`` line).

:func:`run` returns each command with the output the text shows and the one
it gave, so a test can compare them.
"""

from __future__ import annotations

import re
import shlex
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from retrokit.cli import main

REPO = Path(__file__).resolve().parent.parent
DOCUMENT = REPO / "docs" / "integrate.md"
SECTION = "## Your own game, from a ROM"
SHOWN_DATA = "~/.local/share/retrokit"
_BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.MULTILINE | re.DOTALL)


@dataclass(frozen=True)
class Step:
    """One command of the walkthrough: what the text shows under it, and what it printed."""

    line: int
    command: str
    shown: str
    printed: str  # with the data folder written as the text writes it
    data: str  # the data folder it ran with

    def matches(self) -> bool:
        """Whether it printed what the text shows, whitespace aside.

        ``validate`` wraps its messages by their length, and the test's data
        folder is longer than the ``~/.local/share/retrokit`` shown in its place,
        so a path may be cut at another place.
        """
        return _squash(self.printed).replace(_squash(self.data), SHOWN_DATA) == _squash(self.shown)


def _squash(text: str) -> str:
    return "".join(text.split())


def section(text: str) -> tuple[int, str]:
    """The walkthrough's text, and the line of the document it starts on."""
    start = text.index(SECTION)
    end = text.find("\n## ", start + len(SECTION))
    return text.count("\n", 0, start), text[start : end if end >= 0 else len(text)]


def blocks(text: str) -> Iterator[tuple[int, str, str]]:
    """Each fenced block of the walkthrough: its line in the document, its language and its text."""
    first, body = section(text)
    for match in _BLOCK.finditer(body):
        yield first + body.count("\n", 0, match.start()) + 2, match.group(1), match.group(2)


def commands(console: str) -> Iterator[tuple[int, str, str]]:
    """Each ``$ command`` of a console block, with its offset in lines and the output shown under it."""
    lines = console.splitlines()
    starts = [i for i, line in enumerate(lines) if line.startswith("$ ")]
    for n, i in enumerate(starts):
        end = starts[n + 1] if n + 1 < len(starts) else len(lines)
        yield i, lines[i][2:], "\n".join(lines[i + 1 : end]).strip("\n")


def run(workdir: Path, data: Path, capsys: pytest.CaptureFixture[str]) -> Iterator[Step]:
    """Run the walkthrough in ``workdir`` (the current folder) with ``data`` as the data folder; yield each command."""

    def local(text: str) -> str:
        return text.replace(SHOWN_DATA, str(data))

    for line, language, text in blocks(DOCUMENT.read_text(encoding="utf-8")):
        if language == "python":
            exec(compile(text, f"{DOCUMENT.name}:{line}", "exec"), {"__name__": "walkthrough"})  # noqa: S102
        elif language == "yaml" and text.startswith(("# file: ", "# append to: ")):
            head, _, content = text.partition("\n")
            path = Path(local(head.split(": ", 1)[1].strip()))
            mode = "w" if head.startswith("# file: ") else "a"
            with open(path, mode, encoding="utf-8") as f:
                f.write(content)
        elif language == "console":
            for offset, command, shown in commands(text):
                argv = shlex.split(local(command))
                assert argv[0] == "retrokit", f"{DOCUMENT.name}:{line + offset}: only retrokit commands run here"
                capsys.readouterr()
                main(argv[1:])
                out, err = capsys.readouterr()
                errors = [e for e in err.splitlines() if e.startswith("retrokit:")]
                printed = "\n".join([*out.rstrip("\n").splitlines(), *errors]).replace(str(data), SHOWN_DATA)
                yield Step(line + offset, command, shown, printed.strip("\n"), str(data))
