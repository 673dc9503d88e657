"""Running a walkthrough of the docs (a section of commands and their output) as written.

docs/integrate.md has three: "Your own game, from a ROM" (a header-patched
Dasher on the Genesis), "An Atari 2600 game, from ale-py's ROMs"
(Galaxian) and "An NES game, in under 25 commands" (a title-patched Hopper). A walkthrough's blocks run in order in one working folder, with a
fresh data folder shown in the text as ``~/.local/share/retrokit``:

- a ``python`` block is executed (it makes or copies the ROM);
- a ``yaml`` block whose first line is ``# file: PATH`` is that file's text,
  written by hand; ``# append to: PATH`` is text added at its end;
- a ``yaml`` block whose first line is ``# written by the commands above: PATH``
  is shown, not run: :meth:`Walkthrough.written` gives it, for a test to compare
  with the file the commands wrote;
- any other block is shown, not run;
- a ``console`` block holds ``$ retrokit ...`` commands, each followed by
  what it prints (standard output, then any ``retrokit: error:`` line).

:meth:`Walkthrough.run` returns each command with the output the text shows
and the one it gave, so a test can compare them.
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
SHOWN_DATA = "~/.local/share/retrokit"
BY_HAND = ("# file: ", "# append to: ")
WRITTEN = "# written by the commands above: "
_BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.MULTILINE | re.DOTALL)


@dataclass(frozen=True)
class Step:
    """One command of a walkthrough: what the text shows under it, and what it printed."""

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


@dataclass(frozen=True)
class Walkthrough:
    """The section of ``document`` under the heading ``heading`` (``## ...``), up to the next one of its level."""

    document: Path
    heading: str

    def section(self) -> tuple[int, str]:
        """The walkthrough's text, and the line of the document it starts on."""
        text = self.document.read_text(encoding="utf-8")
        start = text.index(self.heading + "\n")
        level = self.heading.split(" ", 1)[0]
        end = text.find(f"\n{level} ", start + len(self.heading))
        return text.count("\n", 0, start), text[start : end if end >= 0 else len(text)]

    def blocks(self) -> Iterator[tuple[int, str, str]]:
        """Each fenced block of the walkthrough: its line in the document, its language and its text."""
        first, body = self.section()
        for match in _BLOCK.finditer(body):
            yield first + body.count("\n", 0, match.start()) + 2, match.group(1), match.group(2)

    def by_hand(self) -> list[str]:
        """The first line of each file written by hand (``# file: PATH``, ``# append to: PATH``)."""
        return [
            text.partition("\n")[0]
            for _, language, text in self.blocks()
            if language == "yaml" and text.startswith(BY_HAND)
        ]

    def written(self) -> list[tuple[str, str]]:
        """Each file the text shows as the commands left it: its path as shown, and its text below that line."""
        return [
            (head[len(WRITTEN) :].strip(), content)
            for _, language, text in self.blocks()
            if language == "yaml" and text.startswith(WRITTEN)
            for head, _, content in [text.partition("\n")]
        ]

    def run(self, workdir: Path, data: Path, capsys: pytest.CaptureFixture[str]) -> Iterator[Step]:
        """Run it in ``workdir`` (the current folder) with ``data`` as the data folder; yield each command."""
        name = self.document.name

        def local(text: str) -> str:
            return text.replace(SHOWN_DATA, str(data))

        for line, language, text in self.blocks():
            if language == "python":
                exec(compile(text, f"{name}:{line}", "exec"), {"__name__": "walkthrough"})  # noqa: S102
            elif language == "yaml" and text.startswith(BY_HAND):
                head, _, content = text.partition("\n")
                path = Path(local(head.split(": ", 1)[1].strip()))
                with open(path, "w" if head.startswith(BY_HAND[0]) else "a", encoding="utf-8") as f:
                    f.write(content)
            elif language == "console":
                for offset, command, shown in commands(text):
                    argv = shlex.split(local(command))
                    assert argv[0] == "retrokit", f"{name}:{line + offset}: only retrokit commands run here"
                    capsys.readouterr()
                    main(argv[1:])
                    out, err = capsys.readouterr()
                    errors = [e for e in err.splitlines() if e.startswith("retrokit:")]
                    printed = "\n".join([*out.rstrip("\n").splitlines(), *errors]).replace(str(data), SHOWN_DATA)
                    yield Step(line + offset, command, shown, printed.strip("\n"), str(data))


def commands(console: str) -> Iterator[tuple[int, str, str]]:
    """Each ``$ command`` of a console block, with its offset in lines and the output shown under it."""
    lines = console.splitlines()
    starts = [i for i, line in enumerate(lines) if line.startswith("$ ")]
    for n, i in enumerate(starts):
        end = starts[n + 1] if n + 1 < len(starts) else len(lines)
        yield i, lines[i][2:], "\n".join(lines[i + 1 : end]).strip("\n")


INTEGRATE = REPO / "docs" / "integrate.md"
RUNNER = Walkthrough(INTEGRATE, "## Your own game, from a ROM")
GALAXIAN = Walkthrough(INTEGRATE, "## An Atari 2600 game, from ale-py's ROMs")
NES = Walkthrough(INTEGRATE, "## An NES game, in under 25 commands")
